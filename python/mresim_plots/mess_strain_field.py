"""Strain and stress fields from the node displacements of a 3D run, for strain_map_*.png.
No drawing here.

From the displacement gradient G = du/dX per cell (mess_lattice.LatticeGrid.
displacement_gradient):
  linear (small) strain   eps = (G + G^T) / 2
  Green strain            E = (F^T F - I) / 2 = (G + G^T + G^T G) / 2, F = I + G; zero for any
                          rigid rotation, where eps is not
  Hooke stress            sigma = lambda tr(eps) I + 2 mu eps, of the linear strain, with the
                          lattice's own shear and bulk moduli (Section 4.2.3; docs/lattice.md):
                          physical profile mu = E / (2 (1 + nu)), K = E / (3 (1 - 2 nu)), the
                          run's E and nu; seed profile mu = 2E/5, K = kappa + 2E/3 with
                          kappa = E (4 nu - 1) / (2 (1 + nu) (1 - 2 nu)) (eq. 4.22);
                          lambda = K - 2 mu / 3. Meaningful in the polymer only: the particle
                          cells (10^4 times stiffer) are left out of stress maps.
"""

import numpy as np

from .view_options import TENSOR_COMPONENTS

DEFAULT_E = 9e3  # Pa, [model] youngs_modulus's default
DEFAULT_NU = 0.47  # [model] poisson_ratio's default
_INDEX = {"x": 0, "y": 1, "z": 2}


def linear_strain(grad):
    return 0.5 * (grad + np.swapaxes(grad, -1, -2))


def green_strain(grad):
    return 0.5 * (grad + np.swapaxes(grad, -1, -2) + np.swapaxes(grad, -1, -2) @ grad)


def lame(youngs_modulus, poisson_ratio, profile="physical"):
    """(lambda, mu) of the lattice, Pa."""
    e, nu = float(youngs_modulus), float(poisson_ratio)
    if profile == "seed":
        mu = 0.4 * e
        kappa = e * (4.0 * nu - 1.0) / (2.0 * (1.0 + nu) * (1.0 - 2.0 * nu))
        bulk = kappa + 2.0 * e / 3.0
    else:
        mu = e / (2.0 * (1.0 + nu))
        bulk = e / (3.0 * (1.0 - 2.0 * nu))
    return bulk - 2.0 * mu / 3.0, mu


def run_lame(run, profile):
    model = run.config.get("model", {})
    return lame(model.get("youngs_modulus", DEFAULT_E), model.get("poisson_ratio", DEFAULT_NU),
                profile)


def hooke_stress(eps, lam, mu):
    trace = np.trace(eps, axis1=-2, axis2=-1)
    return lam * trace[..., None, None] * np.eye(3) + 2.0 * mu * eps


def deviator(t):
    return t - np.trace(t, axis1=-2, axis2=-1)[..., None, None] / 3.0 * np.eye(3)


def von_mises(sigma):
    """sqrt(3/2 s:s), s the deviatoric stress: the uniaxial stress of the same distortion."""
    s = deviator(sigma)
    return np.sqrt(1.5 * np.sum(s * s, axis=(-2, -1)))


def equivalent_strain(eps):
    """sqrt(2/3 e:e), e the deviatoric strain: the von Mises equivalent strain (equals the
    strain of a uniaxial stretch of an incompressible solid)."""
    e = deviator(eps)
    return np.sqrt(2.0 / 3.0 * np.sum(e * e, axis=(-2, -1)))


def component(t, name):
    """'xz' -> t[..., 0, 2]."""
    return t[..., _INDEX[name[0]], _INDEX[name[1]]]


class FieldMap:
    """One --field-map: its symbol, title and unit, whether it is per node (displacement) or
    per cell, signed (diverging colours about zero) or not, and whether particle cells are
    left out (stresses)."""

    def __init__(self, name, symbol, title, unit, nodal, signed, polymer_only=False):
        self.name, self.symbol, self.title, self.unit = name, symbol, title, unit
        self.nodal, self.signed, self.polymer_only = nodal, signed, polymer_only

    @property
    def label(self):
        """Colorbar label: the symbol and the unit."""
        return f"{self.symbol} ({self.unit})" if self.unit else self.symbol


def field_maps():
    um = "\u00b5m"
    maps = {"u": FieldMap("u", r"$|u|$", "displacement", um, True, False)}
    for c in "xyz":
        maps[f"u{c}"] = FieldMap(f"u{c}", rf"$u_{c}$", "displacement", um, True, True)
    for c in TENSOR_COMPONENTS:
        maps[f"eps_{c}"] = FieldMap(f"eps_{c}", rf"$\varepsilon_{{{c}}}$", "linear strain", "",
                                    False, True)
        maps[f"green_{c}"] = FieldMap(f"green_{c}", rf"$E_{{{c}}}$", "Green strain", "", False,
                                      True)
        maps[f"sigma_{c}"] = FieldMap(f"sigma_{c}", rf"$\sigma_{{{c}}}$", "Hooke stress", "Pa",
                                      False, True, polymer_only=True)
    maps["eps_eq"] = FieldMap("eps_eq", r"$\varepsilon_{eq}$",
                              "linear strain, von Mises equivalent", "", False, False)
    maps["eps_vol"] = FieldMap("eps_vol", r"tr$\,\varepsilon$", "linear strain, volume change",
                               "", False, True)
    maps["green_eq"] = FieldMap("green_eq", r"$E_{eq}$", "Green strain, von Mises equivalent", "",
                                False, False)
    maps["sigma_vm"] = FieldMap("sigma_vm", r"$\sigma_{vM}$", "Hooke stress, von Mises", "Pa",
                                False, False, polymer_only=True)
    maps["pressure"] = FieldMap("pressure", r"$p = -$tr$\,\sigma/3$", "Hooke stress, pressure",
                                "Pa", False, True, polymer_only=True)
    return maps


FIELD_MAPS = field_maps()


class StepFields:
    """The fields of one step, computed once and evaluated per map name; with `slab` =
    (axis, (first, end)) only in those cell layers (LatticeGrid.slab)."""

    def __init__(self, grid, positions, lam, mu, slab=None):
        self.grid = grid
        self.positions = np.asarray(positions, dtype=float)
        self.lam, self.mu = lam, mu
        self.slab = slab
        self._grad = None
        self._tensors = {}

    @property
    def first(self):
        """The first cell layer of the slab along its axis (0 without a slab)."""
        return self.slab[1][0] if self.slab else 0

    @property
    def grad(self):
        if self._grad is None:
            if self.slab:
                self._grad = self.grid.displacement_gradient(self.positions, *self.slab)
            else:
                self._grad = self.grid.displacement_gradient(self.positions)
        return self._grad

    def tensor(self, kind):
        if kind not in self._tensors:
            if kind == "eps":
                self._tensors[kind] = linear_strain(self.grad)
            elif kind == "green":
                self._tensors[kind] = green_strain(self.grad)
            else:
                self._tensors[kind] = hooke_stress(self.tensor("eps"), self.lam, self.mu)
        return self._tensors[kind]

    def nodal(self, name):
        """Displacement maps, per node (N), in m."""
        u = self.positions - self.grid.x0
        if name == "u":
            return np.linalg.norm(u, axis=1)
        return u[:, _INDEX[name[1]]]

    def cells(self, name):
        """Strain and stress maps, per cell (nx-1, ny-1, nz-1, or the slab's); strains
        dimensionless, stresses in Pa."""
        if name == "eps_eq":
            return equivalent_strain(self.tensor("eps"))
        if name == "green_eq":
            return equivalent_strain(self.tensor("green"))
        if name == "eps_vol":
            return np.trace(self.tensor("eps"), axis1=-2, axis2=-1)
        if name == "sigma_vm":
            return von_mises(self.tensor("sigma"))
        if name == "pressure":
            return -np.trace(self.tensor("sigma"), axis1=-2, axis2=-1) / 3.0
        kind, c = name.split("_")
        return component(self.tensor(kind), c)
