"""The view figures of the 3D runs (python/mresim_plots/mess_views*.py, mess_animation.py) on
synthetic run directories (mess_fixtures.py) and, when an mresim binary is around (MRESIM_BIN),
on a small real run; the view options of mresim_plot.py.

    /usr/bin/python3 -m unittest discover python/tests -p 'test_mess_views*'
"""

import glob
import os
import subprocess
import sys
import unittest

import h5py
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))  # python/
import mess_fixtures  # noqa: E402
from test_plots import SCRIPT, PlotTestCase  # noqa: E402

from mresim_plots import mess, mess_views, view_options  # noqa: E402
from mresim_plots.common import Run  # noqa: E402

# The figures every run with node positions gets without options (fixture: 9 x 7 x 13 nodes,
# l_e = 1 um, particle 0 at y = 3.5 um -> the nearest node layer y = 4 um).
INITIAL = ["initial_configuration.png", "particle_nodes_orthographic.png", "particle_voxels.png"]


def default_figures(last_step):
    return INITIAL + ["lattice_cut.png", f"magnetization_cut_step{last_step:04d}.png",
                      f"strain_map_step{last_step:04d}_y4.00um.png"]


def views_of(directory, **options):
    """plot_views in process with the given view options (as the command line gives them)."""
    run = Run(directory, view_options.parse(**options))
    mess_views.plot_views(run, mess.MessData(run))
    return run


def written(run):
    return sorted(os.path.basename(p) for p in run.written)


def set_positions(directory, positions_of_step):
    """Replaces DIR/positions/step_NNNNNN.h5 (fixture positions="files") by
    positions_of_step(initial positions, step)."""
    with h5py.File(os.path.join(directory, "results.h5"), "r") as f:
        x0 = f["lattice/initial_positions"][()]
    for path in glob.glob(os.path.join(directory, "positions", "step_*.h5")):
        step = int(os.path.basename(path)[5:11])
        with h5py.File(path, "w") as g:
            g["positions"] = positions_of_step(x0, step)


class MessViewsTest(PlotTestCase):
    def test_default_figures_of_a_run_with_positions(self):
        d = mess_fixtures.make_magnetostriction(self.dir("ms"), positions="results")
        run = views_of(d)
        self.assertEqual(written(run), sorted(default_figures(10)))
        for path in run.written:
            self.assert_nontrivial_png(path)
        self.assertEqual([(p.axis, p.layer, p.tag) for p in run.views.planes], [(1, 4, "y4.00um")])
        self.assertEqual(run.views.steps, [10])

    def test_position_files_and_a_strain_run(self):
        d = mess_fixtures.make_strain(self.dir("strain"), positions="files")
        run = views_of(d)
        self.assertEqual(written(run), sorted(default_figures(43)))
        self.assertIn(r"$\gamma$ = 0.1 rad", run.views.step_label(43))

    def test_no_positions_no_views_and_options_are_refused(self):
        d = mess_fixtures.make_hysteresis(self.dir("hyst"))
        self.assertEqual(written(views_of(d)), [])
        with self.assertRaisesRegex(view_options.OptionError,
                                    "--step, --animate: .* has no node positions .*"
                                    r"\[output\] node_positions = true"):
            views_of(d, steps=["0"], animate=True)

    def test_steps_planes_and_particle_name_the_files(self):
        d = mess_fixtures.make_magnetostriction(self.dir("ms_opts"), positions="results")
        run = views_of(d, steps=["2-3", "last"], planes=["x@1", "z=mid", "y=2.2um", "x"],
                       particle="1", field_maps=["eps_xz", "sigma_vm"])
        # x@1 and x (particle 1) are the same layer: drawn once
        tags = [p.tag for p in run.views.planes]
        self.assertEqual(tags, ["x4.00um", "z6.00um", "y2.00um"])
        self.assertEqual(run.views.steps, [2, 3, 10])
        expected = list(INITIAL)
        for step in (2, 3, 10):
            for tag in tags:
                expected += [f"lattice_cut_step{step:04d}_{tag}.png",
                             f"magnetization_cut_step{step:04d}_{tag}.png",
                             f"strain_map_step{step:04d}_{tag}.png"]
        self.assertEqual(written(run), sorted(expected))
        self.assertEqual(run.views.particle, 1)

    def test_particle_alone_names_the_lattice_cut_but_not_the_magnetization_cut(self):
        d = mess_fixtures.make_magnetostriction(self.dir("ms_particle"), positions="results")
        run = views_of(d, particle="1")
        self.assertIn("lattice_cut_step0010_y4.00um.png", written(run))
        self.assertIn("magnetization_cut_step0010.png", written(run))

    def test_option_values_the_run_cannot_honour(self):
        d = mess_fixtures.make_magnetostriction(self.dir("ms_bad"), positions="results")
        cases = [
            (dict(steps=["11"]), r"--step 11: the run has 11 step\(s\), numbered 0 to 10"),
            (dict(steps=["9-12"]), r"--step 9-12: the run has 11 step\(s\)"),
            (dict(particle="2"), r"--particle 2: the run has 2 particle\(s\), numbered 0 to 1"),
            (dict(planes=["y@5"]), r"--plane 'y@5': the run has 2 particle\(s\)"),
            (dict(planes=["z=20um"]), r"--plane 'z=20um': z = 2e-05 m is outside the lattice; "
                                      r"allowed: 0 to 1.2e-05 m"),
        ]
        for options, message in cases:
            with self.subTest(options=options):
                with self.assertRaisesRegex(view_options.OptionError, message):
                    views_of(d, **options)
        with h5py.File(os.path.join(d, "results.h5"), "a") as f:
            del f["positions/step_000004"]
        with self.assertRaisesRegex(view_options.OptionError,
                                    r"--step 3-5: no node positions for step 4 \(steps with "
                                    r"positions: 0-3, 5-10\)"):
            views_of(d, steps=["3-5"])

    def test_three_frame_animation(self):
        d = mess_fixtures.make_magnetostriction(self.dir("ms_anim"), positions="results")
        run = views_of(d, steps=["0,5,10"], animate=True)
        movies = [p for p in run.written if os.path.basename(p).startswith("animation.")]
        self.assertEqual(len(movies), 1)
        if movies[0].endswith(".gif"):
            from PIL import Image

            with Image.open(movies[0]) as image:
                self.assertEqual(image.n_frames, 3)
                frames = []
                for k in range(3):
                    image.seek(k)
                    frames.append(np.asarray(image.convert("L"), dtype=float))
            # the lattice moves from frame to frame (the fixture's bump grows with the step)
            self.assertGreater(np.abs(frames[2] - frames[0]).mean(), 0.1)
        else:
            self.assertGreater(os.path.getsize(movies[0]), 10_000)

    def test_strain_map_of_an_affine_deformation_is_uniform(self):
        # x = A X: every quad of the cut has the same strain; the figure draws it.
        a = np.array([[1.02, 0.05, 0.0], [0.0, 0.99, 0.01], [0.03, 0.0, 1.04]])
        d = mess_fixtures.make_strain(self.dir("affine"), positions="files")
        set_positions(d, lambda x0, step: x0 @ a.T)
        run = Run(d, view_options.parse(steps=["5"], field_maps=["green_xz"]))
        data = mess.MessData(run)
        views = mess_views.make_views(run, data)
        from mresim_plots import mess_strain_field, mess_views_fields

        plane = views.planes[0]
        fields = mess_strain_field.StepFields(views.grid, views.positions.load(5), views.lam,
                                              views.mu, slab=(1, views.grid.slab(1, plane.layer)))
        self.assertEqual(fields.grad.shape[1], 2)  # the two cell layers about the cut
        values, nodal = mess_views_fields.map_values(views, fields, views.planes[0], "green_xz")
        self.assertFalse(nodal)
        np.testing.assert_allclose(values, 0.5 * (a.T @ a)[0, 2], rtol=1e-10)
        stress, _ = mess_views_fields.map_values(views, fields, views.planes[0], "sigma_vm")
        inside = mess_views_fields.particle_faces(views, views.planes[0])
        self.assertTrue(np.all(np.isnan(stress[inside])))  # particles: no Hooke stress
        self.assertTrue(np.all(np.isfinite(stress[~inside])))
        mess_views.plot_views(run, data)
        self.assert_nontrivial_png(os.path.join(d, "figures", "strain_map_step0005_y4.00um.png"))


class PlotScriptOptionsTest(PlotTestCase):
    """mresim_plot.py's view options: parsed into Run.options; wrong ones exit with 2."""

    def script(self, *args):
        return subprocess.run([sys.executable, SCRIPT, *args], capture_output=True, text=True,
                              timeout=300)

    def test_options_reach_run_options(self):
        import mresim_plot
        from mresim_plots import PLOTTERS

        d = mess_fixtures.make_magnetostriction(self.dir("ms"), positions="results")
        seen = {}
        saved = PLOTTERS["mess_magnetostriction"]
        def plotter(run):
            seen.update(run.options)
            run.views = None  # as plot_views does: the options were used

        PLOTTERS["mess_magnetostriction"] = plotter
        try:
            from contextlib import redirect_stdout
            from io import StringIO

            with redirect_stdout(StringIO()):
                status = mresim_plot.main(["mresim_plot.py", d, "--step", "1,last", "--plane",
                                           "z=mid", "--plane", "x@1", "--particle", "1",
                                           "--field-map", "u,eps_zx", "--animate"])
        finally:
            PLOTTERS["mess_magnetostriction"] = saved
        self.assertEqual(status, 0)
        self.assertEqual(seen["step"], [("index", 1), ("last",)])
        self.assertEqual([(p["axis"], p["kind"]) for p in seen["plane"]],
                         [(2, "mid"), (0, "particle")])
        self.assertEqual(seen["particle"], 1)
        self.assertEqual(seen["field_map"], ["u", "eps_xz"])
        self.assertTrue(seen["animate"])

    def test_wrong_values_exit_2_with_one_line(self):
        d = mess_fixtures.make_magnetostriction(self.dir("ms_bad"), positions="results")
        cases = [
            (["--step", "x"], "mresim_plot: error: --step 'x': 'x' is not a step; allowed: "),
            (["--plane", "q"], "mresim_plot: error: --plane 'q': 'q' is not a plane; allowed: "),
            (["--field-map", "stress"], "mresim_plot: error: --field-map 'stress': unknown map"),
            (["--particle", "one"], "mresim_plot: error: --particle 'one': must be a particle"),
            (["--bogus"], "mresim_plot: error: unrecognized arguments: --bogus"),
        ]
        for args, message in cases:
            with self.subTest(args=args):
                result = self.script(d, *args)
                self.assertEqual(result.returncode, 2, result.stderr)
                self.assertTrue(result.stderr.startswith(message), result.stderr)
                self.assertEqual(result.stderr.count("\n"), 1, result.stderr)

    def test_view_options_of_other_run_types_exit_2(self):
        import fixtures

        d = fixtures.make_curve(self.dir("curve"), "froehlich_kennelly")
        result = self.script(d, "--step", "0", "--animate")
        self.assertEqual(result.returncode, 2, result.stderr)
        self.assertIn("--step, --animate: view options apply to the 3D run types", result.stderr)
        self.assertIn("not to froehlich_kennelly", result.stderr)

    def test_an_option_the_run_cannot_honour_exits_2(self):
        # As mess.plot will call plot_views: the plotter raises OptionError, main says why.
        import mresim_plot
        from mresim_plots import PLOTTERS

        d = mess_fixtures.make_magnetostriction(self.dir("ms_99"), positions="results")
        saved = PLOTTERS["mess_magnetostriction"]
        PLOTTERS["mess_magnetostriction"] = lambda run: mess_views.plot_views(
            run, mess.MessData(run))
        try:
            from contextlib import redirect_stderr
            from io import StringIO

            err = StringIO()
            with redirect_stderr(err):
                status = mresim_plot.main(["mresim_plot.py", d, "--step", "99"])
        finally:
            PLOTTERS["mess_magnetostriction"] = saved
        self.assertEqual(status, 2)
        self.assertEqual(err.getvalue(), "mresim_plot: error: --step 99: the run has 11 "
                         "step(s), numbered 0 to 10\n")


def find_mresim():
    binary = os.environ.get("MRESIM_BIN", "")
    return binary if binary and os.access(binary, os.X_OK) else None


# A pair in a small box, clustered by the field: n_d = 1 (l_e = 1 um), 1,800 nodes, 2 steps.
REAL_RUN = """
[run]
type = "mess_hysteresis"
title = "view figures test: two particles, S = 5 um"
[model]
profile = "physical"
discretization_order = 1
[particles]
radius = 1.5e-6
placement = "chain"
count = 2
separation = 5e-6
axis = "z"
[box]
size = [9e-6, 9e-6, 14e-6]
[field]
magnitudes = [0.0, 0.04]
sequence = "up"
[output]
node_positions = true
checkpoint_every = 0
"""


@unittest.skipUnless(find_mresim(), "set MRESIM_BIN=path/to/mresim to draw the views of a real run")
class RealRunViewsTest(PlotTestCase):
    def test_views_of_a_real_run(self):
        toml = os.path.join(self.tmp, "pair.toml")
        with open(toml, "w") as fh:
            fh.write(REAL_RUN)
        out = os.path.join(self.tmp, "pair")
        result = subprocess.run([find_mresim(), "run", toml, "--out", out, "--no-plot",
                                 "--threads", "1"], capture_output=True, text=True, timeout=600)
        self.assertEqual(result.returncode, 0, result.stderr)
        run = views_of(out, steps=["all"], planes=["y", "z=mid"], animate=True)
        names = written(run)
        for expected in INITIAL + ["strain_map_step0001_y4.00um.png", "animation.gif"]:
            if expected == "animation.gif" and "animation.mp4" in names:
                continue
            self.assertIn(expected, names)
        for path in run.written:
            if path.endswith(".png"):
                self.assert_nontrivial_png(path)
        # The physics the maps show: the faces are held, so the box keeps its shape, and the
        # particles (10^4 times stiffer) hardly strain while the polymer about them does.
        from mresim_plots import mess_strain_field

        views = run.views
        x = views.positions.load(1)
        grid = views.grid
        boundary = np.any((grid.index == 0) | (grid.index == np.array(grid.shape) - 1), axis=1)
        self.assertLess(np.max(np.abs(x[boundary] - grid.x0[boundary])), 1e-12)
        eq = mess_strain_field.equivalent_strain(
            mess_strain_field.linear_strain(grid.displacement_gradient(x)))
        particle = grid.cell_particle() >= 0
        self.assertTrue(np.any(particle))
        self.assertGreater(np.max(eq[~particle]), 1e-3)
        self.assertLess(np.max(eq[particle]), 0.01 * np.max(eq[~particle]))


if __name__ == "__main__":
    unittest.main()
