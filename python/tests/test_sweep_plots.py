"""The cross-run figures of `mresim plot SWEEPDIR` (mresim_plots/sweep.py) on a synthetic sweep
directory: a collected.h5 as `mresim collect` writes it, three finished points over a volume
fraction and one failed point.

    /usr/bin/python3 -m unittest python/tests/test_sweep_plots.py
"""

import json
import os
import shutil
import subprocess
import sys
import tempfile
import unittest

import h5py
import matplotlib

matplotlib.use("Agg")
import matplotlib.image  # noqa: E402
import numpy as np  # noqa: E402

PYTHON_DIR = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCRIPT = os.path.join(PYTHON_DIR, "mresim_plot.py")
KEY = "particles.volume_fraction"
FRACTIONS = [0.03, 0.05, 0.07]
FIELDS = [0.0, 0.04, 0.08]


def _strings(f, path, values):
    f.create_dataset(path, data=np.array(values, dtype=object), dtype=h5py.string_dtype())


def make_sweep(directory, with_modulus=True):
    """A sweep directory as `mresim sweep` + `mresim collect` leave it (only what the figures
    read): points 0-2 finished, point 3 failed."""
    os.makedirs(directory)
    fractions = FRACTIONS + [0.09]
    with open(os.path.join(directory, "sweep.json"), "w") as fh:
        json.dump({"keys": [KEY], "points": [{"index": i, "parameters": {KEY: v}}
                                              for i, v in enumerate(fractions)]}, fh)
    status = ["finished"] * 3 + ["failed"]
    with h5py.File(os.path.join(directory, "collected.h5"), "w") as f:
        f.attrs["parameters"] = KEY
        f.create_dataset("points/point", data=np.arange(4.0))
        _strings(f, "points/status", status)
        f.create_dataset(f"points/{KEY}", data=np.array(fractions))
        if not with_modulus:
            return
        rows = [(p, b) for p in range(3) for b in FIELDS] + [(3, np.nan)]
        point = np.array([r[0] for r in rows], dtype=float)
        b = np.array([r[1] for r in rows])
        phi = np.array([fractions[int(p)] for p in point])
        # G_eff rising with the field, the more so the more particles.
        g = 3e3 * (1 + phi * 40 * b / 0.08)
        g[-1] = np.nan
        mr = np.where(np.isfinite(g), (g / 3e3 - 1) * 100, np.nan)
        f.create_dataset("modulus/point", data=point)
        _strings(f, "modulus/status", [status[int(p)] for p in point])
        f.create_dataset(f"modulus/{KEY}", data=phi)
        f.create_dataset("modulus/B_T", data=b)
        f.create_dataset("modulus/G_eff_Pa", data=g)
        valid = np.isfinite(g).astype(float)
        valid[1] = 0.0  # one invalid fit: drawn hollow and grey
        f.create_dataset("modulus/valid", data=valid)
        f.create_dataset("modulus/mr_effect_percent", data=mr)
        f.create_dataset("modulus/mr_effect_valid", data=np.isfinite(mr).astype(float))


class SweepPlotTest(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.mkdtemp(prefix="mresim_sweep_plot_test_")
        self.dir = os.path.join(self.tmp, "sweep")

    def tearDown(self):
        shutil.rmtree(self.tmp, ignore_errors=True)

    def plot(self, *options):
        return subprocess.run([sys.executable, SCRIPT, self.dir, *options], capture_output=True,
                              text=True, timeout=120)

    def test_draws_modulus_against_field_and_mr_effect_against_the_parameter(self):
        make_sweep(self.dir)
        result = self.plot()
        self.assertEqual(result.returncode, 0, result.stderr)
        figures = os.path.join(self.dir, "figures")
        self.assertEqual(sorted(os.listdir(figures)), ["sweep_modulus.png", "sweep_mr_effect.png"])
        for name in os.listdir(figures):
            image = matplotlib.image.imread(os.path.join(figures, name))
            self.assertGreaterEqual(min(image.shape[:2]), 400, name)
            self.assertGreater(image[..., :3].std(), 0.02, f"{name} is nearly blank")
        self.assertIn("wrote 2 figure(s)", result.stdout)

    def test_mr_effect_curves_are_one_per_nonzero_field_over_the_swept_values(self):
        sys.path.insert(0, PYTHON_DIR)
        from mresim_plots import sweep  # pylint: disable=import-outside-toplevel
        make_sweep(self.dir)
        drawn = []
        original = sweep.Sweep.save

        def keep_axes(figures, fig, name):
            drawn.append((name, [(line.get_label(), np.asarray(line.get_xdata()).tolist())
                                 for line in fig.axes[0].get_lines()]))
            original(figures, fig, name)

        sweep.Sweep.save = keep_axes
        try:
            sweep.plot(sweep.Sweep(self.dir))
        finally:
            sweep.Sweep.save = original
        mr_lines = dict(drawn)["sweep_mr_effect.png"]
        curves = [(label, x) for label, x in mr_lines if "mT" in label]
        self.assertEqual([label for label, _ in curves], ["|B| = 40 mT", "|B| = 80 mT"])
        for _, x in curves:
            self.assertEqual(x, FRACTIONS)  # the failed point is left out
        modulus_curves = [label for label, _ in dict(drawn)["sweep_modulus.png"]
                          if label.startswith(KEY)]
        self.assertEqual(len(modulus_curves), 3)

    def test_a_sweep_without_modulus_tables_is_a_clear_error(self):
        make_sweep(self.dir, with_modulus=False)
        result = self.plot()
        self.assertEqual(result.returncode, 1)
        self.assertIn("wrote no modulus table", result.stderr)

    def test_view_options_are_refused_for_a_sweep_directory(self):
        make_sweep(self.dir)
        result = self.plot("--step", "last")
        self.assertEqual(result.returncode, 2)
        self.assertIn("--step: view options apply to run directories", result.stderr)


if __name__ == "__main__":
    unittest.main()
