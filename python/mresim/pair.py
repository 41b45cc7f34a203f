"""The two-dipole models of Chapters 2-3 at single states, for quick exploration.

A :class:`Pair` is described by the run file's two-dipole tables (``[material]``,
``[springs]``, ``[penalty]``, ``[field]``, ``[solver]``, ``[critical_fields]``; docs/run-files.md),
with the same defaults, validation and error messages as ``mresim run``::

    from mresim import pair

    p = pair.Pair(springs={"k": 0.04, "rest_separation": 9e-6}, field={"max": 0.5})
    p.energy(8e-6, 0.2)["total"]              # J, at S = 8 um along x, B = 0.2 T along the field
    p.relax(0.2)["distance"]                   # the relaxed centre distance at 0.2 T
    loop = p.hysteresis()                      # arrays named as results.h5 /cases/<i>
    p.critical_fields()["HC2"]                 # T

Conventions (as in the run files and results.h5): separations d = r1 - r2 in metres, either a
distance S (the pair along x) or a vector [x, y, z]; fields as B = mu0 H in tesla, either a
number (along the pair's ``field.angle`` from x in the xz-plane) or a vector; moments in units
of Ms (m1 = m2 by symmetry); energies in joules. Arrays of separations give arrays back.
"""

import numpy as np

from . import _core
from .runs import _override_arguments

#: Eq. 2.10: the largest S0 (m) at which a saturated pair along the field clusters, for spring
#: constant k (N/m); radius and saturation_magnetization default to the Section 2.4 spheres.
clustering_threshold_separation = _core.clustering_threshold_separation
#: Eq. 2.10 solved for k: the largest spring constant (N/m) at which a pair at S0 clusters.
clustering_threshold_stiffness = _core.clustering_threshold_stiffness


def puljiz_stiffness(shear_modulus, radius, rest_separation):
    """Eqs. 2.8-2.9: the three-spring constants {"k0", "k12"} (N/m) from the polymer's shear
    modulus G (Pa), the sphere radius R and the zero-field separation S0 (m)."""
    k0, k12 = _core.puljiz_stiffness(shear_modulus, radius, rest_separation)
    return {"k0": k0, "k12": k12}


def field_direction(angle_deg):
    """Unit vector of a field at angle theta_H (degrees) from the pair axis x, in the xz-plane."""
    return np.asarray(_core.field_direction(float(angle_deg)))


def _as_arrays(value):
    """Dict values as numpy arrays (lists of bools and ints from the extension included)."""
    if isinstance(value, dict):
        return {key: _as_arrays(v) for key, v in value.items()}
    return np.asarray(value) if isinstance(value, (list, np.ndarray)) else value


def _squeezed(value):
    """A one-state result without its leading axis."""
    if isinstance(value, dict):
        return {key: _squeezed(v) for key, v in value.items()}
    if isinstance(value, np.ndarray):
        return value[0] if value.ndim == 1 else value.reshape(value.shape[1:])
    return value


class Pair:
    """Two magnetizable spheres joined by one spring (``springs.model = "single"``) or three
    (``"three"``).

    ``config``: a dict of tables, TOML text or a run-file path (a ``pair_hysteresis`` file
    works; pick one of its ``[[case]]`` tables with ``case=`` index or label). Tables may also
    be given as keywords: ``Pair(springs={"k": 0.04}, material={"susceptibility": 3})``.
    ``overrides``: ``--set`` style, as for :class:`mresim.Run`.
    Raises :class:`mresim.ConfigError` for bad input, with the command line's message.
    """

    def __init__(self, config=None, *, overrides=None, case=None, **tables):
        if config is None:
            config = {}
        if tables:
            if not isinstance(config, dict):
                raise TypeError("tables as keywords need config to be a dict (or None)")
            config = {**config, **tables}
        self._model = _core.PairModel(config, _override_arguments(overrides), case)
        self.parameters = self._model.parameters()
        """The resolved parameters: radius, saturation_magnetization, susceptibility,
        spring_model, rest_separation, k12, k0 (N/m), penalty, field_max, field_step,
        field_angle (deg), critical_field_tolerance (T), label."""

    # --- inputs --------------------------------------------------------------------------------

    def field_vector(self, field):
        """B (T) as a 3-vector: a number is taken along ``field.angle``."""
        field = np.asarray(field, dtype=float)
        if field.ndim == 0:
            return float(field) * field_direction(self.parameters["field_angle"])
        if field.shape != (3,):
            raise ValueError(f"field: expected a number or [x, y, z] (T), got shape {field.shape}")
        return field

    @staticmethod
    def _separations(separation):
        """(n x 3 separations, whether one state was given)."""
        d = np.asarray(separation, dtype=float)
        if d.ndim == 0:
            return np.array([[float(d), 0.0, 0.0]]), True
        if d.ndim == 1 and d.shape != (3,):
            return np.column_stack([d, np.zeros_like(d), np.zeros_like(d)]), False
        if d.shape == (3,):
            return d.reshape(1, 3), True
        if d.ndim == 2 and d.shape[1] == 3:
            return d, False
        raise ValueError(
            f"separation: expected S, [x, y, z], n distances or n x 3 vectors (m), got shape {d.shape}")

    def _at_states(self, method, separation, field):
        d, single = self._separations(separation)
        out = _as_arrays(method(d, self.field_vector(field)))
        return _squeezed(out) if single else out

    # --- states --------------------------------------------------------------------------------

    def energy(self, separation, field):
        """Terms of eqs. 2.3/2.4 (J) with the magnetization relaxed at each separation:
        {"total", "zeeman", "dipole", "self", "spring", "anchor", "penalty"}."""
        return self._at_states(self._model.energy, separation, field)

    def gradient(self, separation, field):
        """dE/dd (J/m), the exact gradient of the total energy with respect to d = r1 - r2."""
        d, single = self._separations(separation)
        g = np.asarray(self._model.gradient(d, self.field_vector(field)))
        return g[0] if single else g

    def magnetization(self, separation, field):
        """(moment of each sphere in units of Ms (3-vector per state), saturated (bool))."""
        d, single = self._separations(separation)
        m, saturated = self._model.magnetization(d, self.field_vector(field))
        m, saturated = np.asarray(m), np.asarray(saturated)
        return (m[0], bool(saturated[0])) if single else (m, saturated)

    def relax(self, field, start=None):
        """The relaxed state at B = ``field`` (T, along ``field.angle``), from ``start`` (a
        separation vector, m; default the zero-field configuration S0 x). Returns the
        quantities of one loop point: field, separation, distance, rotation (deg), moment,
        magnetization_along_field, saturated, energy {term: J}, iterations, converged."""
        start = None if start is None else self._separations(start)[0][0]
        return _squeezed(_as_arrays(self._model.relax(float(field), start)))

    # --- sweeps --------------------------------------------------------------------------------

    def hysteresis(self):
        """The loop 0 -> +field.max -> -field.max -> +field.max in steps of field.step, each
        point relaxed from the previous one, as arrays named like results.h5 /cases/<i>:
        field, branch, separation (n x 3), distance, rotation, moment (n x 3),
        magnetization_along_field, saturated, energy {term}, iterations, converged."""
        return _as_arrays(self._model.hysteresis())

    def critical_fields(self):
        """The bistable range on the first quadrant, as a ``pair_map`` point computes it:
        {"hysteresis", "HC1", "HC2", "dH", "uncertainty", "dH_uncertainty", "dH_resolved",
        "converged", "valid", "problem"}, fields in T."""
        return self._model.critical_fields()

    def clustering_threshold_separation(self):
        """Eq. 2.10 for this pair's material and spring constant (single spring: k)."""
        return clustering_threshold_separation(
            self._single_k(), self.parameters["radius"], self.parameters["saturation_magnetization"])

    def _single_k(self):
        p = self.parameters
        return p["k12"] if p["spring_model"] == "single" else 0.5 * p["k0"] + p["k12"]

    def __repr__(self):
        p = self.parameters
        return (f"<mresim.pair.Pair {p['spring_model']} spring, S0 = {p['rest_separation']:g} m, "
                f"k12 = {p['k12']:g} N/m, k0 = {p['k0']:g} N/m>")
