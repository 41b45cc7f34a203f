"""The strain and stress fields behind strain_map_*.png (python/mresim_plots/mess_lattice.py,
mess_strain_field.py) on imposed deformations with known answers, and the syntax of the view
options (view_options.py).

    /usr/bin/python3 -m unittest discover python/tests -p 'test_mess_views*'
"""

import math
import os
import sys
import unittest

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))  # python/
from mresim_plots import mess_strain_field as sf  # noqa: E402
from mresim_plots import view_options  # noqa: E402
from mresim_plots.mess_lattice import LatticeGrid, cut_cells  # noqa: E402

LE = 0.5e-6


def block(shape=(5, 4, 6), shuffle=False, origin=(1e-6, -2e-6, 0.0)):
    """Initial positions of a block of nodes (m); shuffled: in a random order, so that nothing
    relies on mresim's node numbering."""
    idx = np.stack(np.meshgrid(*[np.arange(n) for n in shape], indexing="ij"), axis=-1)
    x0 = np.asarray(origin) + LE * idx.reshape(-1, 3).astype(float)
    if shuffle:
        x0 = x0[np.random.default_rng(3).permutation(x0.shape[0])]
    return x0


def rotation(axis, angle):
    axis = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + math.sin(angle) * k + (1 - math.cos(angle)) * k @ k


class DisplacementGradientTest(unittest.TestCase):
    def test_affine_deformation_is_exact(self):
        # x = A X + b: du/dX = A - I in every cell, whatever the node order.
        rng = np.random.default_rng(7)
        a = np.eye(3) + 0.3 * rng.standard_normal((3, 3))
        b = np.array([1e-7, -3e-7, 2e-7])
        x0 = block(shuffle=True)
        grid = LatticeGrid(x0, LE)
        grad = grid.displacement_gradient(x0 @ a.T + b)
        self.assertEqual(grad.shape, (4, 3, 5, 3, 3))
        np.testing.assert_allclose(grad, np.broadcast_to(a - np.eye(3), grad.shape), atol=1e-12)
        np.testing.assert_allclose(sf.green_strain(grad)[1, 1, 1],
                                   0.5 * (a.T @ a - np.eye(3)), atol=1e-12)
        np.testing.assert_allclose(sf.linear_strain(grad)[2, 0, 4],
                                   0.5 * (a + a.T) - np.eye(3), atol=1e-12)

    def test_rigid_rotation_has_no_green_strain_but_linear_strain(self):
        x0 = block()
        r = rotation((1.0, 2.0, -0.5), math.radians(30))
        grad = LatticeGrid(x0, LE).displacement_gradient(x0 @ r.T)
        green = sf.green_strain(grad)
        eps = sf.linear_strain(grad)
        self.assertLess(np.max(np.abs(green)), 1e-12)
        self.assertLess(np.max(sf.equivalent_strain(green)), 1e-12)
        # the linear strain of a rotation by theta: (R + R^T)/2 - I, of size 1 - cos(theta)
        np.testing.assert_allclose(eps[0, 0, 0], 0.5 * (r + r.T) - np.eye(3), atol=1e-12)
        self.assertGreater(np.max(np.abs(eps)), 0.05)

    def test_gradient_is_taken_at_the_cell_centre(self):
        # u_x = (X^2 + X Z) / L: the trilinear element's du_x/dX at the centre is
        # (X1^2 - X0^2)/(L l_e) + Z_c / L = (2 X_c + Z_c) / L and du_x/dZ = X_c / L, the exact
        # derivatives at the cell centre (X_c, Z_c): not those of one edge of the cell.
        x0 = block(origin=(0.0, 0.0, 0.0))
        length = 1e-6
        x = x0.copy()
        x[:, 0] += (x0[:, 0] ** 2 + x0[:, 0] * x0[:, 2]) / length
        grid = LatticeGrid(x0, LE)
        grad = grid.displacement_gradient(x)
        xc = (np.arange(4) + 0.5) * LE
        zc = (np.arange(5) + 0.5) * LE
        np.testing.assert_allclose(grad[:, 1, :, 0, 0], (2 * xc[:, None] + zc[None, :]) / length,
                                   rtol=1e-12)
        np.testing.assert_allclose(grad[:, 1, :, 0, 2], np.broadcast_to(xc[:, None] / length,
                                                                       (4, 5)), rtol=1e-12)
        self.assertLess(np.max(np.abs(grad[..., 0, 1])), 1e-15)
        self.assertLess(np.max(np.abs(grad[..., 1:, :])), 1e-15)

    def test_non_finite_positions_give_nan_cells_only_there(self):
        x0 = block()
        x = x0.copy()
        grid = LatticeGrid(x0, LE)
        corner = grid.node[0, 0, 0]
        x[corner] = np.nan
        grad = grid.displacement_gradient(x)
        self.assertTrue(np.all(np.isnan(grad[0, 0, 0])))
        self.assertEqual(np.count_nonzero(np.isnan(grad[..., 0, 0])), 1)

    def test_irregular_positions_are_refused(self):
        x0 = block()
        x0[3, 0] += 0.2 * LE
        with self.assertRaisesRegex(Exception, "cubic grid"):
            LatticeGrid(x0, LE)


class HookeTest(unittest.TestCase):
    def test_physical_profile_has_the_runs_e_and_nu(self):
        e, nu = 9e3, 0.47
        lam, mu = sf.lame(e, nu, "physical")
        self.assertAlmostEqual(mu, e / (2 * (1 + nu)))
        self.assertAlmostEqual(lam, e * nu / ((1 + nu) * (1 - 2 * nu)), places=6)
        # uniaxial stress sigma_zz = s with lateral strain -nu s/E: sigma_xx = sigma_yy = 0
        s = 100.0
        eps = np.diag([-nu * s / e, -nu * s / e, s / e])
        sigma = sf.hooke_stress(eps, lam, mu)
        np.testing.assert_allclose(sigma, np.diag([0.0, 0.0, s]), atol=1e-9)
        self.assertAlmostEqual(float(sf.von_mises(sigma)), s, places=9)

    def test_seed_profile_uses_the_lattices_moduli(self):
        # docs/lattice.md, E = 9 kPa, nu = 0.47: seed lattice G = 3600 Pa, K = 50,898 Pa;
        # physical G = 3061.2 Pa, K = 50,000 Pa.
        lam, mu = sf.lame(9e3, 0.47, "seed")
        self.assertAlmostEqual(mu, 3600.0, places=6)
        self.assertAlmostEqual(lam + 2 * mu / 3, 50898.0, delta=1.0)
        lam, mu = sf.lame(9e3, 0.47, "physical")
        self.assertAlmostEqual(mu, 3061.2, delta=0.05)
        self.assertAlmostEqual(lam + 2 * mu / 3, 50000.0, delta=1e-6)

    def test_shear_and_dilation(self):
        lam, mu = sf.lame(9e3, 0.3)
        g = 0.01
        shear = np.array([[0, g, 0], [g, 0, 0], [0, 0, 0]])
        sigma = sf.hooke_stress(shear, lam, mu)
        self.assertAlmostEqual(sigma[0, 1], 2 * mu * g)
        self.assertAlmostEqual(float(np.trace(sigma)), 0.0)
        self.assertAlmostEqual(float(sf.von_mises(sigma)), math.sqrt(3) * 2 * mu * g)
        self.assertAlmostEqual(float(sf.equivalent_strain(shear)), 2 * g / math.sqrt(3))
        dilation = 1e-3 * np.eye(3)
        pressure = -np.trace(sf.hooke_stress(dilation, lam, mu)) / 3
        self.assertAlmostEqual(pressure, -(lam + 2 * mu / 3) * 3e-3)
        self.assertAlmostEqual(float(sf.von_mises(sf.hooke_stress(dilation, lam, mu))), 0.0)

    def test_every_map_name_is_computed(self):
        x0 = block()
        a = np.eye(3) + np.array([[0.01, 0.02, 0.0], [0.0, -0.01, 0.03], [0.01, 0.0, 0.02]])
        fields = sf.StepFields(LatticeGrid(x0, LE), x0 @ a.T, *sf.lame(9e3, 0.47))
        g = a - np.eye(3)
        eps = 0.5 * (g + g.T)
        for name in view_options.FIELD_MAP_NAMES:
            spec = sf.FIELD_MAPS[name]
            values = fields.nodal(name) if spec.nodal else fields.cells(name)
            self.assertTrue(np.all(np.isfinite(values)), name)
        np.testing.assert_allclose(fields.cells("eps_yz"), eps[1, 2], atol=1e-14)
        np.testing.assert_allclose(fields.cells("green_xz"),
                                   (0.5 * (a.T @ a - np.eye(3)))[0, 2], atol=1e-14)
        np.testing.assert_allclose(fields.nodal("uz"), (x0 @ g.T)[:, 2], atol=1e-20)


class CutCellsTest(unittest.TestCase):
    def test_faces_average_the_cells_on_both_sides(self):
        grid = LatticeGrid(block(), LE)  # 4 x 3 x 5 cells
        values = np.zeros((4, 3, 5))
        values[:, 0, :] = 1.0
        values[:, 1, :] = 3.0
        inside = cut_cells(grid, 1, 1, values)  # layer y = 1: cells y = 0 and 1
        np.testing.assert_allclose(inside, np.full((4, 5), 2.0))
        np.testing.assert_allclose(cut_cells(grid, 1, 0, values), 1.0)  # the face: one side
        weights = np.ones((4, 3, 5), dtype=bool)
        weights[:, 1, :] = False
        np.testing.assert_allclose(cut_cells(grid, 1, 1, values, weights), 1.0)
        weights[:, 0, :] = False
        self.assertTrue(np.all(np.isnan(cut_cells(grid, 1, 1, values, weights))))
        self.assertEqual(cut_cells(grid, 0, 2, values).shape, (3, 5))  # y-z
        self.assertEqual(cut_cells(grid, 2, 2, values).shape, (4, 3))  # x-y

    def test_a_slab_about_the_cut_gives_the_whole_lattices_values(self):
        x0 = block()
        grid = LatticeGrid(x0, LE)
        x = x0 + 0.05 * LE * np.random.default_rng(5).standard_normal(x0.shape)
        full = sf.StepFields(grid, x, *sf.lame(9e3, 0.47))
        for axis in range(3):
            for layer in range(grid.shape[axis]):
                slab = sf.StepFields(grid, x, *sf.lame(9e3, 0.47),
                                     slab=(axis, grid.slab(axis, layer)))
                for name in ("eps_xz", "green_eq", "sigma_vm"):
                    np.testing.assert_allclose(
                        cut_cells(grid, axis, layer, slab.cells(name), first=slab.first),
                        cut_cells(grid, axis, layer, full.cells(name)), rtol=1e-13,
                        err_msg=f"{name}, axis {axis}, layer {layer}")

    def test_particle_cells_are_those_with_eight_particle_corners(self):
        x0 = block(shape=(4, 4, 4), origin=(0.0, 0.0, 0.0))
        grid0 = LatticeGrid(x0, LE)
        pid = np.full(x0.shape[0], -1)
        pid[grid0.node[1:3, 1:3, 1:3].ravel()] = 0
        pid[grid0.node[0, 0, 0]] = 1
        cells = LatticeGrid(x0, LE, pid).cell_particle()
        self.assertEqual(np.count_nonzero(cells == 0), 1)
        self.assertEqual(cells[1, 1, 1], 0)
        self.assertEqual(np.count_nonzero(cells == 1), 0)


class ViewOptionSyntaxTest(unittest.TestCase):
    def test_steps(self):
        self.assertEqual(view_options.parse_steps(["0,3-5", "last", "all"]),
                         [("index", 0), ("range", 3, 5), ("last",), ("all",)])
        for bad in ["-1", "5-3", "x", "", "1,,2", "2.5"]:
            with self.assertRaisesRegex(view_options.OptionError, "--step"):
                view_options.parse_steps([bad])

    def test_planes(self):
        planes = view_options.parse_planes(["y", "x@2,z=4.5e-6", "y=4.5um", "z=mid",
                                            "x=3\u00b5m"])
        self.assertEqual([(p["axis"], p["kind"]) for p in planes],
                         [(1, "particle"), (0, "particle"), (2, "coordinate"),
                          (1, "coordinate"), (2, "mid"), (0, "coordinate")])
        self.assertEqual(planes[1]["value"], 2)
        self.assertAlmostEqual(planes[2]["value"], 4.5e-6)
        self.assertAlmostEqual(planes[3]["value"], 4.5e-6)
        self.assertAlmostEqual(planes[5]["value"], 3e-6)
        for bad in ["w", "y=", "y=abc", "y@", "y@-1", "xy", "y=4.5mm"]:
            with self.assertRaisesRegex(view_options.OptionError, "--plane .*allowed"):
                view_options.parse_planes([bad])

    def test_field_maps(self):
        self.assertEqual(view_options.parse_field_maps(["u,eps_zx", "sigma_vm", "u"]),
                         ["u", "eps_xz", "sigma_vm"])
        with self.assertRaisesRegex(view_options.OptionError,
                                    "--field-map 'strain': unknown map 'strain'; allowed: u, "):
            view_options.parse_field_maps(["strain"])

    def test_particle(self):
        self.assertEqual(view_options.parse_particle("3"), 3)
        self.assertIsNone(view_options.parse_particle(None))
        with self.assertRaisesRegex(view_options.OptionError, "--particle '-1'"):
            view_options.parse_particle("-1")


if __name__ == "__main__":
    unittest.main()
