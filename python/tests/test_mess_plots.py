"""Figures of the 3D run types (python/mresim_plots/mess.py) from synthetic results.h5 files
(tests/mess_fixtures.py).

    /usr/bin/python3 -m unittest discover python/tests -k Mess
"""

import os
import sys
import unittest

import h5py

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))  # python/
import mess_fixtures  # noqa: E402
from test_plots import PlotTestCase  # noqa: E402
from test_mess_views import INITIAL, default_figures  # noqa: E402

COMMON = ["energies.png", "particle_magnetization.png"]
FIELD_SWEEP = COMMON + ["separation_magnetization.png"]
LOAD = COMMON + ["energies_vs_strain.png", "pair_orientation.png"]  # strain and stress runs
MODULUS = LOAD + ["energy_density_fit.png", "modulus.png", "mr_effect.png"]


class MessPlotTest(PlotTestCase):
    def test_hysteresis_without_positions(self):
        d = mess_fixtures.make_hysteresis(self.dir("hyst"))
        self.assert_figures(d, FIELD_SWEEP, absent=["lattice_cut.png", "modulus.png",
                                                    "energies_vs_strain.png",
                                                    "magnetostriction.png"])

    def test_hysteresis_with_position_files(self):
        d = mess_fixtures.make_hysteresis(self.dir("hyst_pos"), positions="files")
        self.assert_figures(d, FIELD_SWEEP + default_figures(last_step=50))

    def test_magnetostriction_with_positions_in_results(self):
        d = mess_fixtures.make_magnetostriction(self.dir("ms"), positions="results")
        self.assert_figures(d, FIELD_SWEEP + default_figures(last_step=10))

    def test_strain_with_kink_and_position_files(self):
        d = mess_fixtures.make_strain(self.dir("strain"), positions="files")
        self.assert_figures(d, MODULUS + default_figures(last_step=43),
                            absent=["separation_magnetization.png", "stress_strain.png"])

    def test_strain_without_reference_modulus(self):
        # modulus at the first field NaN: the MR effect is undefined everywhere.
        d = mess_fixtures.make_strain(self.dir("strain_nan"), positions=None, mr_nan=True)
        self.assert_figures(d, MODULUS)

    def test_strain_without_measured_strain_uses_load(self):
        d = mess_fixtures.make_strain(self.dir("strain_old"), positions=None)
        with h5py.File(os.path.join(d, "results.h5"), "a") as f:
            del f["steps/measured_strain"]
        self.assert_figures(d, MODULUS)

    def test_strain_without_analysis_draws_curves_only(self):
        d = mess_fixtures.make_strain(self.dir("strain_noanalysis"), positions=None)
        with h5py.File(os.path.join(d, "results.h5"), "a") as f:
            del f["analysis"]
        self.assert_figures(d, LOAD + ["energy_density_fit.png"],
                            absent=["modulus.png", "mr_effect.png"])

    def test_initial_lattice_alone_gives_the_initial_views_but_no_cuts(self):
        d = mess_fixtures.make_strain(self.dir("strain_initial"), positions="initial")
        self.assert_figures(d, MODULUS + INITIAL,
                            absent=["lattice_cut.png", "magnetization_cut_step0043.png"])

    def test_stress(self):
        d = mess_fixtures.make_stress(self.dir("stress"))
        self.assert_figures(d, MODULUS + ["stress_strain.png"], absent=["lattice_cut.png"])

    def test_positions_without_initial_positions_are_skipped(self):
        d = mess_fixtures.make_magnetostriction(self.dir("ms_noinit"), positions="results")
        with h5py.File(os.path.join(d, "results.h5"), "a") as f:
            del f["lattice/initial_positions"]
        self.assert_figures(d, FIELD_SWEEP, absent=["lattice_cut.png"])

    def test_strain_with_invalid_fit_draws_it_hollow(self):
        d = mess_fixtures.make_strain(self.dir("strain_invalid"), positions=None,
                                      invalid_field=2)
        self.assert_figures(d, MODULUS)

    def test_invalid_fit_is_not_plotted_as_data(self):
        # In process: the figures are kept open and their lines inspected.
        from mresim_plots import common, mess
        d = mess_fixtures.make_strain(self.dir("strain_invalid_lines"), positions=None,
                                      invalid_field=2)
        figures = {}

        class KeepFigures(common.Run):
            def save(self, fig, name):
                figures[name] = fig

        run = KeepFigures(d)
        data = mess.MessData(run)
        mess.modulus(run, data)
        mess.mr_effect(run, data)
        mess.energy_density_fit(run, data)
        invalid_b = data.field_magnitude[2] * 1e3
        for name in ("modulus.png", "mr_effect.png"):
            lines = figures[name].axes[0].get_lines()
            data_lines = [ln for ln in lines if ln.get_label() != mess.INVALID_FIT_LABEL
                          and ln.get_marker() not in ("None", "", None)]
            invalid = [ln for ln in lines if ln.get_label() == mess.INVALID_FIT_LABEL]
            self.assertTrue(data_lines, name)
            for ln in data_lines:
                self.assertNotIn(invalid_b, list(ln.get_xdata()), name)
            self.assertEqual(len(invalid), 1, name)
            self.assertEqual(list(invalid[0].get_xdata()), [invalid_b], name)
            self.assertEqual(invalid[0].get_markerfacecolor(), "none", name)
            self.assertEqual(invalid[0].get_linestyle(), "None", name)
            legend = figures[name].axes[0].get_legend()
            self.assertIsNotNone(legend, name)
            self.assertIn(mess.INVALID_FIT_LABEL, [t.get_text() for t in legend.get_texts()])
        # The energy-density figure draws no parabola for the invalid field and says so.
        ax = figures["energy_density_fit.png"].axes[0]
        labels = [t.get_text() for t in ax.get_legend().get_texts()]
        self.assertTrue(any(t.endswith("no valid fit") for t in labels), labels)
        curves = [ln for ln in ax.get_lines() if ln.get_marker() in ("None", "", None)
                  and len(ln.get_xdata()) == 100]
        self.assertEqual(len(curves), 3)  # 4 fields, one invalid

    def test_missing_steps_fails_with_one_line(self):
        d = mess_fixtures.make_magnetostriction(self.dir("ms_broken"), positions=None)
        with h5py.File(os.path.join(d, "results.h5"), "a") as f:
            del f["steps"]
        from test_plots import plot
        result = plot(d)
        self.assertEqual(result.returncode, 1, result.stdout + result.stderr)
        self.assertEqual(len(result.stderr.strip().splitlines()), 1, result.stderr)
        self.assertIn("/steps", result.stderr)


if __name__ == "__main__":
    unittest.main()
