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
import numpy as np  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))  # python/
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


class KeptFiguresMixin:
    """In-process drawing: a Run whose save() keeps the figures open for inspection."""

    def kept_run(self, directory):
        from mresim_plots import common

        figures = {}

        class Kept(common.Run):
            def save(self, fig, name):
                figures[name] = fig

        run = Kept(directory)
        run.figures = figures
        return run

    def tearDown(self):
        import matplotlib.pyplot as plt
        plt.close("all")
        super().tearDown()


def all_texts(fig):
    """Every string drawn on a figure: titles, labels, legends, tick-free texts."""
    texts = [t.get_text() for t in fig.texts]
    if fig._suptitle is not None:
        texts.append(fig._suptitle.get_text())
    for ax in fig.axes:
        texts += [ax.get_xlabel(), ax.get_ylabel()]
        texts += [ax.get_title(loc=loc) for loc in ("left", "center", "right")]
        texts += [t.get_text() for t in ax.texts]
        if ax.get_legend() is not None:
            texts += [t.get_text() for t in ax.get_legend().get_texts()]
    for legend in fig.legends:
        texts += [t.get_text() for t in legend.get_texts()]
    return [t for t in texts if t]


class PairFigureDetailsTest(KeptFiguresMixin, PlotTestCase):
    def test_unresolved_dh_drawn_hollow_with_a_legend_entry(self):
        from mresim_plots import pair_map
        d = fixtures.make_pair_map(self.dir("k_res"), rows="k")
        marked = fixtures.add_dh_resolved(d)
        self.assertTrue(marked)
        run = self.kept_run(d)
        grid = pair_map.read_grid(run)
        self.assertEqual(sorted(zip(*np.nonzero(pair_map.unresolved(grid)))), sorted(marked))
        pair_map.dh_vs_s0(run, grid)
        ax = run.figures["dH_vs_S0.png"].axes[0]
        hollow = [ln for ln in ax.get_lines() if ln.get_markerfacecolor() == "w"]
        rows = pair_map.selected_rows(grid["rows"].size)
        expected = [r for r in rows if any(m[0] == r for m in marked)]
        self.assertEqual(len(hollow), len(expected))
        for ln, r in zip(hollow, expected):
            cols = sorted(c for rr, c in marked if rr == r)
            np.testing.assert_allclose(ln.get_xdata(), grid["s0"][cols])
        # the filled markers of each row are its resolved points only
        filled = [ln for ln in ax.get_lines() if ln.get_marker() == "o"
                  and ln.get_markerfacecolor() != "w"]
        self.assertEqual(len(filled), len(rows))
        for ln, r in zip(filled, rows):
            keep = [c for c in range(grid["s0"].size) if (r, c) not in marked]
            np.testing.assert_allclose(ln.get_xdata(), grid["s0"][keep])
        labels = [t.get_text() for t in ax.get_legend().get_texts()]
        self.assertIn(pair_map.UNRESOLVED_LABEL, labels)

    def test_without_the_flag_nothing_is_hollow(self):
        from mresim_plots import pair_map
        d = fixtures.make_pair_map(self.dir("k_nores"), rows="k")
        run = self.kept_run(d)
        grid = pair_map.read_grid(run)
        self.assertIsNone(grid["resolved"])
        pair_map.dh_vs_s0(run, grid)
        pair_map.critical_fields_map(run, grid)
        ax = run.figures["dH_vs_S0.png"].axes[0]
        self.assertFalse([ln for ln in ax.get_lines() if ln.get_markerfacecolor() == "w"])
        labels = [t.get_text() for t in ax.get_legend().get_texts()]
        self.assertNotIn(pair_map.UNRESOLVED_LABEL, labels)
        # the critical fields are mu0 H (T)
        titles = [a.get_title() for a in run.figures["critical_fields_map.png"].axes[:3]]
        self.assertTrue(all(r"\mu_0" in t for t in titles), titles)

    def test_contact_line_behind_the_loop_and_typeset_labels(self):
        from mresim_plots import loops, pair_hysteresis
        cases = [dict(label=f"k = 0.04 N/m, S0 = {s0 * 1e6:g} um", model="single", s0=s0,
                      hc1=0.2, hc2=0.8) for s0 in (6e-6, 9e-6)]
        d = fixtures.make_pair_hysteresis(self.dir("contact"), cases)
        run = self.kept_run(d)
        summary = run.table("summary.csv")
        pair_cases = pair_hysteresis.read_cases(run, summary)
        pair_hysteresis.displacement(run, pair_cases)
        fig = run.figures["displacement.png"]
        for ax, case in zip(fig.axes, pair_cases):
            contact_um = (2 * fixtures.RADIUS - case["s0"]) * 1e6
            contact = [ln for ln in ax.get_lines() if len(ln.get_ydata()) == 2
                       and np.allclose(ln.get_ydata(), contact_um)]
            self.assertEqual(len(contact), 1, case["label"])
            loop = [ln for ln in ax.get_lines() if len(ln.get_xdata()) > 2]
            self.assertLess(contact[0].get_zorder(), min(ln.get_zorder() for ln in loop))
            self.assertEqual(contact[0].get_linestyle(), loops.CONTACT_STYLE["linestyle"])
        texts = all_texts(fig)
        self.assertIn("k = 0.04 N/m, $S_0$ = 6 µm", texts)
        self.assertIn(r"contact, $S = 2R$", texts)
        self.assertFalse([t for t in texts if " um" in t or r"$\mu$m" in t], texts)


class TypographyTest(unittest.TestCase):
    def test_typeset(self):
        from mresim_plots.typography import typeset
        self.assertEqual(typeset("(a) k = 0.4 N/m, S0 = 6 um"), "(a) k = 0.4 N/m, $S_0$ = 6 µm")
        self.assertEqual(typeset("three springs, theta_H = 10 deg"),
                         r"three springs, $\theta_H$ = 10°")
        self.assertEqual(typeset("mu0 H_C1 < B < mu0H_C2"),
                         r"$\mu_0 H_{C1}$ < B < $\mu_0 H_{C2}$")
        self.assertEqual(typeset("shear, Phi = 3 %, theta = 90"), "shear, Φ = 3 %, θ = 90")
        # words that only contain the ASCII spellings stay; mathtext is left alone
        self.assertEqual(typeset("column S0_m, drum, Phil"), "column S0_m, drum, Phil")
        self.assertEqual(typeset(r"$x$ in um"), r"$x$ in um")


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
