"""Runs python/mresim_plot.py on synthetic run directories (tests/fixtures.py) and, when an
mresim binary is around, on real runs of the examples.

    /usr/bin/python3 -m unittest discover python/tests
"""

import glob
import os
import shutil
import subprocess
import sys
import tempfile
import unittest

import matplotlib

matplotlib.use("Agg")
import matplotlib.image  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import fixtures  # noqa: E402

PYTHON_DIR = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
REPO = os.path.dirname(PYTHON_DIR)
SCRIPT = os.path.join(PYTHON_DIR, "mresim_plot.py")


def plot(directory):
    return subprocess.run([sys.executable, SCRIPT, directory], capture_output=True, text=True,
                          timeout=300)


class PlotTestCase(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.mkdtemp(prefix="mresim_plot_test_")

    def tearDown(self):
        shutil.rmtree(self.tmp, ignore_errors=True)

    def dir(self, name):
        return os.path.join(self.tmp, name)

    def assert_figures(self, directory, expected, absent=()):
        result = plot(directory)
        self.assertEqual(result.returncode, 0, result.stderr)
        figures = os.path.join(directory, "figures")
        found = sorted(os.path.basename(p) for p in glob.glob(os.path.join(figures, "*.png")))
        self.assertEqual(found, sorted(expected))
        for name in expected:
            self.assert_nontrivial_png(os.path.join(figures, name))
        for name in absent:
            self.assertFalse(os.path.exists(os.path.join(figures, name)), name)

    def assert_nontrivial_png(self, path):
        self.assertGreater(os.path.getsize(path), 15_000, path)
        image = matplotlib.image.imread(path)
        self.assertGreaterEqual(min(image.shape[:2]), 400, path)
        self.assertGreater(image[..., :3].std(), 0.02, f"{path} is nearly blank")


class PairHysteresisTest(PlotTestCase):
    def test_single_case(self):
        d = fixtures.make_pair_hysteresis(self.dir("single"), [
            dict(label="k = 0.04 N/m", model="single", s0=9e-6, hc1=0.2, hc2=0.8)])
        self.assert_figures(d, ["magnetization.png", "displacement.png"],
                            absent=["rotation.png", "configuration.png"])

    def test_three_cases_with_three_springs(self):
        d = fixtures.make_pair_hysteresis(self.dir("three"), [
            dict(label="single, tanh", model="single", s0=9e-6, hc1=0.2, hc2=0.8),
            dict(label="three springs, theta_H = 10 deg", model="three", s0=9e-6, hc1=0.25,
                 hc2=0.7, angle=10.0),
            dict(label="three springs, theta_H = 80 deg", model="three", s0=9e-6, hc1=0.0,
                 hc2=0.0, angle=80.0)])
        self.assert_figures(d, ["magnetization.png", "displacement.png", "rotation.png",
                                "configuration.png"])

    def test_nine_case_grid(self):
        cases = [dict(label=f"({chr(97 + i)}) k = {k} N/m, S0 = {s0 * 1e6:g} um", model="single",
                      s0=s0, hc1=0.1 * (i % 3), hc2=0.3 * (i % 3))
                 for i, (k, s0) in enumerate((k, s) for k in (0.4, 0.04, 0.004)
                                             for s in (6e-6, 9e-6, 12e-6))]
        d = fixtures.make_pair_hysteresis(self.dir("grid"), cases)
        self.assert_figures(d, ["magnetization.png", "displacement.png"])

    def test_missing_critical_fields_is_skipped(self):
        d = fixtures.make_pair_hysteresis(self.dir("nocrit"), [
            dict(label="k = 0.04 N/m", model="single", s0=9e-6, hc1=0.2, hc2=0.8)])
        os.remove(os.path.join(d, "critical_fields.csv"))
        self.assert_figures(d, ["magnetization.png", "displacement.png"])


class PairMapTest(PlotTestCase):
    def test_k_map(self):
        d = fixtures.make_pair_map(self.dir("k"), rows="k")
        self.assert_figures(d, ["critical_fields_map.png", "dH_vs_S0.png"])

    def test_k_map_without_threshold(self):
        d = fixtures.make_pair_map(self.dir("k_nothr"), rows="k", threshold=False)
        self.assert_figures(d, ["critical_fields_map.png", "dH_vs_S0.png"])

    def test_angle_map(self):
        d = fixtures.make_pair_map(self.dir("angle"), rows="angle")
        self.assert_figures(d, ["critical_fields_map.png", "dH_vs_S0.png"])


class PairEnsembleTest(PlotTestCase):
    def test_ensemble(self):
        d = fixtures.make_pair_ensemble(self.dir("ens"))
        self.assert_figures(d, ["ensemble_first_quadrant.png", "loop_widening.png",
                                "susceptibility.png"])

    def test_ensemble_without_widening(self):
        d = fixtures.make_pair_ensemble(self.dir("ens_nowide"), widening=False)
        self.assert_figures(d, ["ensemble_first_quadrant.png", "susceptibility.png"])


class CurveTest(PlotTestCase):
    def test_froehlich_kennelly(self):
        self.assert_figures(fixtures.make_curve(self.dir("fk"), "froehlich_kennelly"),
                            ["magnetization.png"])

    def test_preisach(self):
        self.assert_figures(fixtures.make_curve(self.dir("pre"), "preisach"),
                            ["magnetization.png"])


class ErrorTest(PlotTestCase):
    def assert_fails(self, directory, words):
        result = plot(directory)
        self.assertEqual(result.returncode, 1, result.stdout + result.stderr)
        lines = result.stderr.strip().splitlines()
        self.assertEqual(len(lines), 1, result.stderr)
        self.assertIn(words, lines[0])

    def test_missing_directory(self):
        self.assert_fails(self.dir("nowhere"), "not a directory")

    def test_missing_results(self):
        os.makedirs(self.dir("empty"))
        self.assert_fails(self.dir("empty"), "no results.h5")

    def test_unknown_run_type(self):
        d = fixtures.make_curve(self.dir("odd"), "preisach")
        import h5py
        with h5py.File(os.path.join(d, "results.h5"), "a") as f:
            f.attrs["run_type"] = "no_such_type"
        self.assert_fails(d, "no_such_type")

    def test_missing_summary(self):
        d = fixtures.make_pair_ensemble(self.dir("nosummary"))
        os.remove(os.path.join(d, "summary.csv"))
        self.assert_fails(d, "summary.csv")

    def test_usage(self):
        result = subprocess.run([sys.executable, SCRIPT], capture_output=True, text=True)
        self.assertEqual(result.returncode, 2)


def find_mresim():
    binary = os.environ.get("MRESIM_BIN", "")
    return binary if binary and os.access(binary, os.X_OK) else None


@unittest.skipUnless(find_mresim(), "set MRESIM_BIN=path/to/mresim to plot real example runs")
class ExampleRunsTest(PlotTestCase):
    """Every examples/*.toml whose run type the binary knows, run and plotted (opt-in: about
    a minute)."""

    def test_examples(self):
        binary = find_mresim()
        types = subprocess.run([binary, "types"], capture_output=True, text=True).stdout
        for toml in sorted(glob.glob(os.path.join(REPO, "examples", "*.toml"))):
            name = os.path.splitext(os.path.basename(toml))[0]
            with open(toml) as fh:
                run_type = next((line.split("=")[1].strip().strip('"') for line in fh
                                 if line.strip().startswith("type")), "")
            if run_type not in types.split():
                continue
            with self.subTest(example=name):
                out = self.dir(name)
                run = subprocess.run([binary, "run", toml, "--out", out, "--no-plot"],
                                     capture_output=True, text=True, timeout=600)
                self.assertEqual(run.returncode, 0, run.stderr)
                result = plot(out)
                self.assertEqual(result.returncode, 0, result.stderr)
                pngs = glob.glob(os.path.join(out, "figures", "*.png"))
                self.assertTrue(pngs)
                for png in pngs:
                    self.assert_nontrivial_png(png)


if __name__ == "__main__":
    unittest.main()
