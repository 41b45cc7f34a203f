"""What the newer 3D figures compute and draw, checked in process on synthetic runs
(tests/mess_fixtures.py): the energy changes against strain and the panels left out
(mess_energies.py), magnetostriction (mess_magnetostriction.py), the pair against strain
(mess_pair_orientation.py), the second modulus fit (mess.py) and the contact line.

    /usr/bin/python3 -m unittest discover python/tests -p 'test_mess_figure_data.py'
"""

import os
import shutil
import sys
import tempfile
import unittest

import h5py
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))  # python/
import mess_fixtures  # noqa: E402
from mresim_plots import (common, loops, mess, mess_energies, mess_magnetostriction,  # noqa: E402
                          mess_pair_orientation)


class KeptFigures(common.Run):
    """A Run whose save() keeps the figures open for inspection instead of writing them."""

    def __init__(self, directory):
        super().__init__(directory)
        self.figures = {}

    def save(self, fig, name):
        self.figures[name] = fig


def visible_titles(fig):
    return [ax.get_title(loc="right") for ax in fig.axes if ax.get_visible()
            and ax.get_title(loc="right")]


def figure_texts(fig):
    texts = [t.get_text() for t in fig.texts]
    for legend in fig.legends:
        texts += [t.get_text() for t in legend.get_texts()]
    return texts


class MessFigureDataTest(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.mkdtemp(prefix="mresim_mess_data_")

    def tearDown(self):
        import matplotlib.pyplot as plt
        plt.close("all")
        shutil.rmtree(self.tmp, ignore_errors=True)

    def strain_run(self, name="strain", **kwargs):
        return mess_fixtures.make_strain(os.path.join(self.tmp, name), positions=None, **kwargs)

    # ------------------------------------------------------------ energies against strain

    def test_changes_against_strain_are_differences_from_zero_strain_at_each_field(self):
        d = self.strain_run()
        written = mess_fixtures.add_known_energies(d)
        run = KeptFigures(d)
        data = mess.MessData(run)
        fields = mess_energies.strain_changes(data)
        self.assertEqual([f.field for f in fields], [0, 1, 2, 3])
        for f in fields:
            self.assertEqual(data.load_value[f.reference], 0.0)
            self.assertEqual(data.field_index[f.reference], f.field)
            x = data.strain[f.steps]
            np.testing.assert_array_equal(x, f.strain)
            self.assertTrue(np.all(np.diff(data.load_index[f.steps]) > 0), "load order")
            for name, (_, slope) in mess_fixtures.KNOWN_ENERGIES.items():
                # E0(k) + slope x^2 - E0(k): the field's constant cancels (up to rounding
                # of E0 ~ 1e-12 J: atol 1e-26 J)
                np.testing.assert_allclose(f.changes[name], slope * x**2, rtol=1e-9,
                                           atol=1e-26, err_msg=f"{name}, field {f.field}")
                np.testing.assert_array_equal(
                    f.changes[name], written[name][f.steps] - written[name][f.reference])

    def test_reference_is_the_zero_load_step_even_when_it_is_not_first(self):
        d = self.strain_run("strain_reordered")
        mess_fixtures.add_known_energies(d)
        with h5py.File(os.path.join(d, "results.h5"), "a") as f:
            # strains -0.05 .. 0.05 rad: zero load in the middle of every field's steps
            f["steps/load_value"][...] = f["steps/load_value"][()] - 0.05
        data = mess.MessData(KeptFigures(d))
        for f in mess_energies.strain_changes(data):
            self.assertAlmostEqual(data.load_value[f.reference], 0.0, places=15)
            self.assertEqual(list(f.steps).index(f.reference), 5)
            self.assertEqual(f.changes["springs"][5], 0.0)

    def test_strain_panels_leave_out_terms_without_change(self):
        d = self.strain_run("strain_panels")
        mess_fixtures.add_known_energies(d)
        run = KeptFigures(d)
        data = mess.MessData(run)
        mess_energies.energies_vs_strain(run, data)
        fig = run.figures["energies_vs_strain.png"]
        titles = visible_titles(fig)
        # dipole, wca, load: zero; self: constant in the strain
        self.assertEqual(titles, ["springs (eq. 4.62)", "volume elements (eq. 4.64)",
                                  "Zeeman (eq. 4.70)", "total"])
        note = " ".join(figure_texts(fig))
        for left_out in ("dipole-dipole", "magnetic self (eq. 4.76)", "WCA", "applied load"):
            self.assertIn(left_out, note)
        # the drawn curves are the changes: the springs panel of field 2 is 2e-13 x^2
        springs = next(ax for ax in fig.axes if ax.get_title(loc="right").startswith("springs"))
        curves = [ln for ln in springs.get_lines() if len(ln.get_xdata()) == 11]
        self.assertEqual(len(curves), 4)
        x = np.asarray(curves[2].get_xdata())
        np.testing.assert_allclose(curves[2].get_ydata(), 2e-13 * x**2, rtol=1e-12)

    def test_field_figure_of_a_strain_run_keeps_constant_terms_but_not_zero_ones(self):
        d = self.strain_run("strain_field_panels")
        mess_fixtures.add_known_energies(d)
        run = KeptFigures(d)
        data = mess.MessData(run)
        mess_energies.energies(run, data)
        fig = run.figures["energies.png"]
        self.assertEqual(visible_titles(fig),
                         ["springs (eq. 4.62)", "volume elements (eq. 4.64)",
                          "Zeeman (eq. 4.70)", "magnetic self (eq. 4.76)", "total"])
        self_panel = next(ax for ax in fig.axes if ax.get_title(loc="right").startswith("magn"))
        values = [ln for ln in self_panel.get_lines() if ln.get_marker() == "o"][0]
        # at zero strain, against |B| in mT: self = 2e-13 k at field index k
        np.testing.assert_allclose(values.get_xdata(), [0.0, 20.0, 50.0, 100.0])
        np.testing.assert_allclose(values.get_ydata(), 2e-13 * np.arange(4), atol=1e-30)

    def test_hysteresis_energies_leave_out_zero_terms(self):
        d = mess_fixtures.make_hysteresis(os.path.join(self.tmp, "hyst"))
        with h5py.File(os.path.join(d, "results.h5"), "a") as f:
            f["steps/energies/wca"][...] = 0.0
            f["steps/energies/load"][...] = 0.0
        run = KeptFigures(d)
        data = mess.MessData(run)
        mess_energies.energies(run, data)
        mess_energies.energies_vs_strain(run, data)  # no strain: nothing
        self.assertEqual(set(run.figures), {"energies.png"})
        titles = visible_titles(run.figures["energies.png"])
        self.assertNotIn("WCA (eq. 4.79)", titles)
        self.assertNotIn("applied load", titles)
        self.assertIn("dipole-dipole (eq. 4.71)", titles)
        self.assertIn("WCA (eq. 4.79)", " ".join(figure_texts(run.figures["energies.png"])))

    def test_nonzero_panels_tolerance(self):
        panels = [("a", "A"), ("b", "B"), ("c", "C")]
        kept, left_out = mess_energies.nonzero_panels(
            panels, {"a": np.array([0.0, 1.0]), "b": np.array([0.0, 5e-10]),
                     "c": np.array([np.nan, 2e-9])})
        self.assertEqual(kept, [("a", "A"), ("c", "C")])
        self.assertEqual(left_out, ["B"])
        kept, left_out = mess_energies.nonzero_panels(panels, {n: np.zeros(2) for n in "abc"})
        self.assertEqual((kept, left_out), ([], ["A", "B", "C"]))

    # ------------------------------------------------------------ magnetostriction

    def test_magnetostriction_drawn_when_present_and_nonzero(self):
        d = mess_fixtures.make_magnetostriction(os.path.join(self.tmp, "ms"), positions=None)
        run = KeptFigures(d)
        mess_magnetostriction.magnetostriction(run, mess.MessData(run))
        self.assertNotIn("magnetostriction.png", run.figures, "absent dataset: skipped")
        expected = mess_fixtures.add_magnetostriction(d)
        run = KeptFigures(d)
        data = mess.MessData(run)
        mess_magnetostriction.magnetostriction(run, data)
        ax = run.figures["magnetostriction.png"].axes[0]
        drawn = [ln for ln in ax.get_lines() if ln.get_marker() == "o"]
        self.assertEqual(len(drawn), 1)  # one leg: 0 -> 100 mT
        np.testing.assert_allclose(drawn[0].get_xdata(), data.b_along * 1e3)
        np.testing.assert_allclose(drawn[0].get_ydata(), expected)

    def test_magnetostriction_all_zero_is_skipped(self):
        d = mess_fixtures.make_magnetostriction(os.path.join(self.tmp, "ms0"), positions=None)
        mess_fixtures.add_magnetostriction(d, values=np.zeros(11))
        run = KeptFigures(d)
        mess_magnetostriction.magnetostriction(run, mess.MessData(run))
        self.assertEqual(run.figures, {})

    def test_magnetostriction_of_a_loop_is_drawn_leg_by_leg(self):
        d = mess_fixtures.make_hysteresis(os.path.join(self.tmp, "hyst_ms"))
        mess_fixtures.add_magnetostriction(d)
        run = KeptFigures(d)
        data = mess.MessData(run)
        mess_magnetostriction.magnetostriction(run, data)
        ax = run.figures["magnetostriction.png"].axes[0]
        self.assertEqual(len([ln for ln in ax.get_lines() if ln.get_marker() == "o"]),
                         np.unique(mess.legs(data.b_along)).size)

    # ------------------------------------------------------------ pair against strain

    def test_pair_orientation_panels(self):
        d = self.strain_run("pair")
        run = KeptFigures(d)
        data = mess.MessData(run)
        mess_pair_orientation.pair_orientation(run, data)
        fig = run.figures["pair_orientation.png"]
        self.assertEqual(len(fig.axes), 1, "no pair_angle: the separation panel alone")
        angles = mess_fixtures.add_pair_angle(d)
        run = KeptFigures(d)
        data = mess.MessData(run)
        mess_pair_orientation.pair_orientation(run, data)
        fig = run.figures["pair_orientation.png"]
        self.assertEqual(len(fig.axes), 2)
        sep_ax, angle_ax = fig.axes
        curves = mess_pair_orientation.pair_curves(data)
        self.assertEqual(len(curves), 4)
        for k, x, s, a in curves:
            steps = np.flatnonzero(data.field_index == k)
            np.testing.assert_allclose(x, data.strain[steps])
            np.testing.assert_allclose(s, data.separation[steps] * 1e6)
            np.testing.assert_allclose(a, angles[steps])  # degrees
        lines = [ln for ln in angle_ax.get_lines() if ln.get_marker() == "o"]
        np.testing.assert_allclose(lines[1].get_ydata(), 5.0 * np.arange(11) + 2.0)
        self.assertIn("µm", sep_ax.get_ylabel())

    def test_pair_orientation_skipped_with_one_particle(self):
        d = self.strain_run("single")
        with h5py.File(os.path.join(d, "results.h5"), "a") as f:
            f["steps/separation"][...] = np.nan
        mess_fixtures.add_pair_angle(d, angles_deg=np.full(44, np.nan))
        run = KeptFigures(d)
        mess_pair_orientation.pair_orientation(run, mess.MessData(run))
        self.assertEqual(run.figures, {})

    # ------------------------------------------------------------ second fit after a kink

    def second_fit_figures(self, name, **kwargs):
        d = self.strain_run(name)
        expected = mess_fixtures.add_second_fit(d, **kwargs)
        run = KeptFigures(d)
        data = mess.MessData(run)
        mess.energy_density_fit(run, data)
        mess.modulus(run, data)
        return run, data, expected

    def test_second_fit_drawn_over_its_own_points_with_both_moduli(self):
        run, data, expected = self.second_fit_figures("second")
        k = expected["field"]
        ax = run.figures["energy_density_fit.png"].axes[0]
        steps = np.flatnonzero(data.field_index == k)
        x = data.strain[steps]
        dashed = [ln for ln in ax.get_lines() if ln.get_linestyle() == "--"
                  and len(ln.get_xdata()) == 100]
        self.assertEqual(len(dashed), 1)
        xs, ys = np.asarray(dashed[0].get_xdata()), np.asarray(dashed[0].get_ydata())
        self.assertAlmostEqual(xs[0], x[7])
        self.assertAlmostEqual(xs[-1], x[10])
        # drawn as u - c1 (the first fit's offset): a x^2/2 + (c2 - c1) = a x^2/2 - 8
        np.testing.assert_allclose(ys, 0.5 * expected["modulus"] * xs**2 - 8.0, rtol=1e-9)
        squares = [ln for ln in ax.get_lines() if ln.get_marker() == "s"]
        self.assertEqual(len(squares), 1)
        np.testing.assert_allclose(squares[0].get_xdata(), x[7:11])
        # the first fit's parabola stays on its 7 points
        solid = [ln for ln in ax.get_lines() if ln.get_linestyle() == "-"
                 and len(ln.get_xdata()) == 100]
        self.assertEqual(len(solid), 4)
        self.assertAlmostEqual(max(np.max(ln.get_xdata()) for ln in solid[3:]), x[6])
        labels = [t.get_text() for t in ax.get_legend().get_texts()]
        both = [t for t in labels if t.startswith(data.field_label(k))]
        self.assertEqual(len(both), 1)
        self.assertIn(f"{data.modulus[k] / 1e3:.3g} kPa", both[0])
        self.assertIn(f"after the kink {expected['modulus'] / 1e3:.3g} kPa", both[0])
        self.assertTrue(any(t.startswith("second fit") and "a x^2/2 + c" in t for t in labels))
        # modulus.png: the second modulus as its own series at that field only
        mod_ax = run.figures["modulus.png"].axes[0]
        diamonds = [ln for ln in mod_ax.get_lines() if ln.get_marker() == "D"]
        self.assertEqual(len(diamonds), 1)
        np.testing.assert_allclose(diamonds[0].get_xdata(), [data.field_magnitude[k] * 1e3])
        np.testing.assert_allclose(diamonds[0].get_ydata(), [expected["modulus"] / 1e3])

    def test_a_legend_of_twelve_fields_goes_below_the_axes_inside_the_figure(self):
        # The Fig. 4.25 helix has twelve fields: on the axes their legend covered the curves and
        # ran past the figure's right edge.
        d = self.strain_run("twelve", fields=np.linspace(0.0, 0.14, 12))
        mess_fixtures.add_second_fit(d)
        run = KeptFigures(d)
        data = mess.MessData(run)
        mess.energy_density_fit(run, data)
        fig = run.figures["energy_density_fit.png"]
        ax = fig.axes[0]
        self.assertIsNone(ax.get_legend())
        self.assertEqual(len(fig.legends), 1)
        legend = fig.legends[0]
        labels = [t.get_text() for t in legend.get_texts()]
        for k in range(12):
            self.assertEqual(sum(t.startswith(data.field_label(k) + ":") for t in labels), 1,
                             labels)
        self.assertTrue(any(t.startswith("second fit after the kink") for t in labels), labels)
        fig.canvas.draw()
        renderer = fig.canvas.get_renderer()
        box = legend.get_window_extent(renderer)
        page = fig.bbox
        self.assertGreaterEqual(box.x0, page.x0)
        self.assertLessEqual(box.x1, page.x1)
        self.assertGreaterEqual(box.y0, page.y0)
        # below the axes with their tick labels and axis label, so it covers no data
        self.assertLessEqual(box.y1, ax.get_tightbbox(renderer).y0)

    def test_second_fit_with_a_stored_slope(self):
        run, data, expected = self.second_fit_figures("second_slope", slope=-40.0)
        ax = run.figures["energy_density_fit.png"].axes[0]
        dashed = [ln for ln in ax.get_lines() if ln.get_linestyle() == "--"
                  and len(ln.get_xdata()) == 100][0]
        xs = np.asarray(dashed.get_xdata())
        np.testing.assert_allclose(dashed.get_ydata(),
                                   0.5 * expected["modulus"] * xs**2 - 40.0 * xs - 8.0,
                                   rtol=1e-9)
        labels = [t.get_text() for t in ax.get_legend().get_texts()]
        self.assertTrue(any("b x" in t for t in labels), labels)

    def test_no_second_fit_without_the_datasets_or_when_invalid(self):
        d = self.strain_run("no_second")
        run = KeptFigures(d)
        data = mess.MessData(run)
        self.assertFalse(any(data.second.ok(k) for k in range(4)))
        mess.energy_density_fit(run, data)
        ax = run.figures["energy_density_fit.png"].axes[0]
        self.assertFalse([ln for ln in ax.get_lines() if ln.get_marker() == "s"])
        mess_fixtures.add_second_fit(d)
        with h5py.File(os.path.join(d, "results.h5"), "a") as f:
            f["analysis/second_valid"][...] = 0
        data = mess.MessData(KeptFigures(d))
        self.assertTrue(data.second.present)
        self.assertFalse(any(data.second.ok(k) for k in range(4)))

    # ------------------------------------------------------------ contact line

    def test_contact_line_is_behind_the_markers_and_labelled(self):
        d = mess_fixtures.make_hysteresis(os.path.join(self.tmp, "contact"))
        run = KeptFigures(d)
        data = mess.MessData(run)
        mess.separation_magnetization(run, data)
        ax = run.figures["separation_magnetization.png"].axes[0]
        contact = [ln for ln in ax.get_lines()
                   if np.allclose(ln.get_ydata(), 2 * mess_fixtures.RADIUS * 1e6)]
        self.assertEqual(len(contact), 1)
        data_lines = [ln for ln in ax.get_lines() if ln.get_marker() == "o"]
        self.assertTrue(data_lines)
        self.assertLess(contact[0].get_zorder(), min(ln.get_zorder() for ln in data_lines))
        self.assertEqual(contact[0].get_linestyle(), loops.CONTACT_STYLE["linestyle"])
        self.assertLess(contact[0].get_linewidth(), min(ln.get_linewidth() for ln in data_lines))
        self.assertEqual(contact[0].get_color(), loops.CONTACT_STYLE["color"])
        labels = [t.get_text() for t in run.figures["separation_magnetization.png"].axes[-1]
                  .get_legend().get_texts()]
        self.assertIn(r"contact, $S = 2R$", labels)


if __name__ == "__main__":
    unittest.main()
