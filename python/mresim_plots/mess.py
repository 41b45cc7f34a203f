"""mess_hysteresis, mess_magnetostriction, mess_strain, mess_stress: runs of the 3D model
(Chapter 4; the results.h5 layout is in docs/outputs-3d.md).

Figures:
  every run      energies.png               energies by term against B (hysteresis,
                                            magnetostriction) or against |B| at zero load
                                            (strain, stress); mess_energies.py
                 particle_magnetization.png centres and M at the last step (Fig. 4.22)
                 lattice_cut.png and the    the deformed lattice cut (Fig. 4.12), the initial
                 other view figures         configuration (Figs. 4.2, 4.3, 4.24), magnetization
                                            cuts (Figs. 4.22, 4.23) and strain maps; only when
                                            node positions were written (mess_views.py)
  hysteresis,    separation_magnetization.png  smallest separation and M/Ms against B (Fig. 4.4)
  magnetostriction  magnetostriction.png    box strain along the field against B, when
                                            /steps/magnetostriction is not zero throughout
                                            (mess_magnetostriction.py)
  strain, stress energies_vs_strain.png     per field, each energy term's change from zero
                                            strain against the strain (Figs. 4.14-4.17 a-f;
                                            mess_energies.py)
                 pair_orientation.png       closest pair's separation and angle to the field
                                            against the strain (mess_pair_orientation.py)
                 energy_density_fit.png     energy density against strain per field, with the
                                            fitted u = a x^2/2 + c and, after a kink, the
                                            second fit (Figs. 4.14g, 4.26; strain runs)
                 modulus.png                G_eff / E_eff against |B|, the second fit's modulus
                                            as a second series (Figs. 4.18, 4.25)
                 mr_effect.png              (modulus / modulus at the first field - 1) x 100 %
  stress         stress_strain.png          applied stress against measured strain, with the
                                            fitted slope
"""

import glob
import math
import os
import re

import h5py
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.lines import Line2D
from matplotlib.patches import Circle

from .common import BRANCH_LINESTYLE, MAG_LABEL, PlotError, case_colors, legend_below
from .loops import CONTACT_STYLE
from .typography import UM_PAREN, suptitle, typeset

# The energy terms are the system's list (src/mresim/mess/terms/energy_term.hpp): results.h5
# lists them in /steps/energies@terms and gives each dataset its `title` and `equation`.
# `self_linearized` (eq. 4.73, reported only) is drawn dashed in the self-energy panel, not in a
# panel of its own. For files without those attributes: the built-in terms and their titles.
ENERGY_PANELS = [
    ("springs", "springs (eq. 4.62)"),
    ("volume", "volume elements (eq. 4.64)"),
    ("zeeman", "Zeeman (eq. 4.70)"),
    ("dipole", "dipole-dipole (eq. 4.71)"),
    ("self", "magnetic self (eq. 4.76)"),
    ("wca", "WCA (eq. 4.79)"),
    ("load", "applied load"),
    ("total", "total"),
]
FIELD_MT_LABEL = r"$B$ along the field direction (mT)"
ABS_FIELD_LABEL = r"$|B_{ext}|$ (mT)"
SEPARATION_COLOR = "#1f3fd6"
MAGNETIZATION_COLOR = "#d81bd8"
DEFAULT_MS = 1.6e6  # A/m, [particles] saturation_magnetization's default
MODULUS_LABELS = {
    "G_eff": (r"$G_{eff}$", "kPa"),
    "E_eff": (r"$E_{eff}$", "kPa"),
    "E_eff (stress)": (r"$E_{eff}$ (stress)", "kPa"),
    "torsion_stiffness": ("torsion stiffness", r"kJ/m$^3$"),
}
STRAIN_LABELS = {
    "G_eff": r"shear strain $\tan\gamma$",
    "E_eff": r"strain $\varepsilon$",
    "E_eff (stress)": r"measured strain $\varepsilon$",
    "torsion_stiffness": "twist angle (rad)",
}


LOAD_RUN_TYPES = ("mess_strain", "mess_stress")


def plot(run):
    # The figure modules import this one: imported here, not at the top.
    from . import mess_energies, mess_magnetostriction, mess_pair_orientation, mess_views

    data = MessData(run)
    mess_energies.energies(run, data)
    if data.load_run:
        mess_energies.energies_vs_strain(run, data)
        if run.run_type == "mess_stress":
            stress_strain(run, data)
        energy_density_fit(run, data)
        if data.has_analysis:  # an unfinished or failed analysis: the curves alone
            modulus(run, data)
            mr_effect(run, data)
        mess_pair_orientation.pair_orientation(run, data)
    else:
        separation_magnetization(run, data)
        mess_magnetostriction.magnetostriction(run, data)
    particle_magnetization(run, data)
    mess_views.plot_views(run, data)  # lattice cuts, initial configuration, maps (with positions)


class MessData:
    """The datasets of results.h5 that the figures use (SI units as stored)."""

    def __init__(self, run):
        self.run = run
        self.load_run = run.run_type in LOAD_RUN_TYPES
        with run.h5() as f:
            if "steps" not in f or "field_projection" not in f["steps"]:
                raise PlotError(f"{run.h5_path} has no /steps/field_projection")
            s = f["steps"]
            self.b_along = np.asarray(s["field_projection"][()], dtype=float)
            n = self.b_along.size
            if n == 0:
                raise PlotError(f"{run.h5_path} has no steps")
            self.field = _array(s, "field", np.zeros((n, 3)))
            self.field_index = _array(s, "field_index", np.zeros(n)).astype(int)
            self.load_index = _array(s, "load_index", np.zeros(n)).astype(int)
            self.load_value = _array(s, "load_value", np.zeros(n))
            self.load_unit = _text(s["load_value"].attrs.get("unit", "")) if "load_value" in s \
                else ""
            # The fit's strain axis (docs/outputs-3d.md); files without it: the applied load.
            self.strain = _array(s, "measured_strain", self.load_value)
            self.energies = {}
            self.energy_titles = {}
            self.energy_order = []
            if "energies" in s:
                for name, dataset in s["energies"].items():
                    self.energies[name] = np.asarray(dataset[()], dtype=float)
                    if "title" in dataset.attrs:
                        title = _text(dataset.attrs["title"])
                        equation = _text(dataset.attrs.get("equation", ""))
                        self.energy_titles[name] = (f"{title} ({equation})"
                                                    if equation.startswith("eq.") else title)
                if "terms" in s["energies"].attrs:
                    self.energy_order = _text(s["energies"].attrs["terms"]).split(",")
            self.energy_density = _array(s, "energy_density", None)
            self.separation = _array(s, "separation", None)
            if self.separation is not None and not np.isfinite(self.separation).any():
                self.separation = None  # fewer than two particles: no pair, all NaN
            # Written by newer runs (docs/outputs-3d.md); None when absent.
            self.pair_angle = _array(s, "pair_angle", None)  # rad, closest pair vs field
            self.magnetostriction = _array(s, "magnetostriction", None)  # box strain along B
            self.box_strain = _array(s, "box_strain", None)  # S x 3
            self.m_along = _array(s, "magnetization_projection", None)
            self.centres = _array(s, "centres", None)
            self.magnetization = _array(s, "magnetization", None)
            lattice = f["lattice"] if "lattice" in f else None
            attrs = lattice.attrs if lattice is not None else {}
            self.element_length = float(attrs.get("element_length", math.nan))
            self.radius = float(attrs.get("particle_radius", math.nan))
            self.box = _array(lattice, "box_lengths", None)
            self.initial_centres = _array(lattice, "initial_centres", None)
            self.initial_positions = _array(lattice, "initial_positions", None)
            self.particle_id = _array(lattice, "particle_id", None)
            # /analysis: one entry per field (strain and stress runs). Without it the per-field
            # curves are drawn without fits.
            a = f["analysis"] if "analysis" in f else None
            self.has_analysis = a is not None and "modulus" in a
            self.modulus_name = _text(a.attrs.get("modulus_name", "")) if a is not None else ""
            self.modulus = _array(a, "modulus", np.zeros(0))
            fields = self.modulus.size
            self.field_magnitude = _array(a, "field_magnitude", np.full(fields, math.nan))
            self.offset = _array(a, "offset", np.zeros(fields))
            self.fit_points = _array(a, "fit_points", np.full(fields, -1)).astype(int)  # -1: all
            # Index of the first fitted point (1 when the zero-strain point was dropped).
            self.first_point = _array(a, "first_point", np.zeros(fields)).astype(int)
            self.mr_effect = _array(a, "mr_effect", np.full(fields, math.nan))
            # Fit validity (docs/outputs-3d.md): invalid fits are drawn hollow and grey, never
            # as data. Files without the flags: a finite modulus counts as valid.
            self.fit_valid = _array(a, "valid", np.isfinite(self.modulus)).astype(bool) \
                & np.isfinite(self.modulus)
            self.fit_problem = [_text(p) for p in a["problem"][()]] \
                if a is not None and "problem" in a else [""] * fields
            mr_default = self.fit_valid & (self.fit_valid[:1] if fields else self.fit_valid)
            self.mr_valid = _array(a, "mr_effect_valid", mr_default).astype(bool) \
                & np.isfinite(self.mr_effect)
            self.second = SecondFit(a, fields)
            self.last_positions = self._last_positions(f)
        ms = run.config.get("particles", {}).get("saturation_magnetization", DEFAULT_MS)
        self.ms = float(ms)

    def _last_positions(self, f):
        """Node positions (N x 3, m) of the last step that has them, or None. Two layouts:
        datasets /positions/step_NNNNNN in results.h5, or files DIR/positions/step_NNNNNN.h5
        holding /positions (what mresim writes, docs/outputs-3d.md)."""
        if "positions" in f and isinstance(f["positions"], h5py.Group):
            names = sorted((k for k in f["positions"] if _step_number(k) is not None),
                           key=_step_number)
            if names:
                return np.asarray(f["positions"][names[-1]][()], dtype=float)
        files = sorted((p for p in glob.glob(self.run.path(os.path.join("positions", "*.h5")))
                        if _step_number(os.path.basename(p)) is not None),
                       key=lambda p: _step_number(os.path.basename(p)))
        if files:
            with h5py.File(files[-1], "r") as g:
                if "positions" in g:
                    return np.asarray(g["positions"][()], dtype=float)
        return None

    def field_groups(self):
        """(field index, step indices in step order) per field of a strain or stress run."""
        return [(k, np.flatnonzero(self.field_index == k)) for k in np.unique(self.field_index)]

    def field_label(self, k):
        """'40 mT', with the direction when the run's fields point different ways."""
        steps = np.flatnonzero(self.field_index == k)
        b = self.field[steps[0]] if steps.size else np.zeros(3)
        text = f"{np.linalg.norm(b) * 1e3:.4g} mT"
        directions = {tuple(np.round(_direction(v), 6)) for v in self.field
                      if np.linalg.norm(v) > 0}
        if len(directions) > 1 and np.linalg.norm(b) > 0:
            theta, phi = _angles(b)
            text += rf" ($\theta$={theta:.0f}°, $\varphi$={phi:.0f}°)"
        return text


def _array(group, name, default):
    if group is None or name not in group:
        return default
    return np.asarray(group[name][()], dtype=float)


def _text(value):
    if isinstance(value, bytes):
        return value.decode("utf-8", "replace")
    if isinstance(value, np.ndarray) and value.shape == ():
        return str(value.item())
    return str(value)


def _step_number(name):
    match = re.fullmatch(r"step_(\d+)(\.h5)?", name)
    return int(match.group(1)) if match else None


def _direction(v):
    n = np.linalg.norm(v)
    return v / n if n > 0 else v


def _angles(b):
    """Polar angle from +z and azimuth from +x (deg), as [field] theta and phi."""
    d = _direction(b)
    return math.degrees(math.acos(max(-1.0, min(1.0, d[2])))), math.degrees(math.atan2(d[1], d[0]))


def legs(field):
    """Leg index per step: a new leg starts after every point where |B| is at its maximum (the
    turning points of a loop; docs/original-code.md#hysteresis-figures)."""
    a = np.abs(field)
    top = np.max(a)
    if top <= 0:
        return np.zeros(field.size, dtype=int)
    turning = np.isclose(a, top, rtol=1e-9, atol=0.0)
    return np.concatenate(([0], np.cumsum(turning)[:-1])).astype(int)


def leg_segments(field, leg, values):
    """(leg, label, x, y) per leg; each leg starts at the previous leg's last point so that the
    drawn loop has no gaps at the turning points."""
    for k in np.unique(leg):
        idx = np.flatnonzero(leg == k)
        if idx[0] > 0:
            idx = np.concatenate(([idx[0] - 1], idx))
        rising = field[idx[-1]] >= field[idx[0]]
        if k == 0:
            label = "initial rise" if rising else "initial descent"
        else:
            label = "rise" if rising else "descent"
        yield k, f"leg {k + 1}: {label}", field[idx], values[idx]


def leg_linestyle(k, leg):
    """Solid for a single leg; else as the pair loops: the initial leg dotted, descents solid,
    later rises dashed (BRANCH_LINESTYLE)."""
    if np.max(leg) == 0:
        return "-"
    return BRANCH_LINESTYLE[0 if k == 0 else (1 if k % 2 == 1 else 2)]


def draw_legs(ax, field, leg, values, color, marker=None):
    for k, _, x, y in leg_segments(field, leg, values):
        ax.plot(x, y, color=color, linestyle=leg_linestyle(k, leg), marker=marker, markersize=3,
                linewidth=1.4)


def leg_legend_handles(field, leg):
    return [Line2D([], [], color="0.3", linestyle=leg_linestyle(k, leg), label=label)
            for k, label, _, _ in leg_segments(field, leg, field)]


# ---------------------------------------------------------------- hysteresis and magnetostriction

def separation_magnetization(run, data):
    """Fig. 4.4: the smallest centre distance and M/Ms against B, two y axes."""
    if data.separation is None and data.m_along is None:
        return
    b_mt = data.b_along * 1e3
    leg = legs(data.b_along)
    fig, ax = plt.subplots(figsize=(7.0, 4.8), layout="constrained")
    handles = []
    top = ax  # the legend goes on the axes drawn last, or the twin's lines cover it
    if data.separation is not None:
        draw_legs(ax, b_mt, leg, data.separation * 1e6, SEPARATION_COLOR, marker="o")
        ax.set_ylabel(f"smallest centre separation {UM_PAREN}", color=SEPARATION_COLOR)
        ax.tick_params(axis="y", colors=SEPARATION_COLOR)
        handles.append(Line2D([], [], color=SEPARATION_COLOR, marker="o", markersize=3,
                              label="separation"))
        contact = 2.0 * data.radius * 1e6
        if math.isfinite(contact) and np.nanmin(data.separation) * 1e6 < 1.5 * contact:
            ax.axhline(contact, **CONTACT_STYLE)
            handles.append(Line2D([], [], label=r"contact, $S = 2R$",
                                  **{k: v for k, v in CONTACT_STYLE.items() if k != "zorder"}))
    if data.m_along is not None:
        ax2 = top = ax.twinx() if data.separation is not None else ax
        draw_legs(ax2, b_mt, leg, data.m_along, MAGNETIZATION_COLOR, marker="s")
        ax2.set_ylabel(MAG_LABEL + " (mean along the field)", color=MAGNETIZATION_COLOR)
        ax2.tick_params(axis="y", colors=MAGNETIZATION_COLOR)
        handles.append(Line2D([], [], color=MAGNETIZATION_COLOR, marker="s", markersize=3,
                              label=MAG_LABEL))
    if np.unique(leg).size > 1:
        handles += leg_legend_handles(b_mt, leg)
    ax.axvline(0.0, color="0.8", linewidth=0.6, zorder=0)
    ax.set_xlabel(FIELD_MT_LABEL)
    ax.grid(alpha=0.25)
    top.legend(handles=handles, fontsize=8, loc="best")
    suptitle(run, fig)
    run.save(fig, "separation_magnetization.png")


# ---------------------------------------------------------------- strain and stress runs

def energy_density_fit(run, data):
    """Fig. 4.14g for every field on one axes: u - c against the strain (c, the first fit's
    offset, differs between fields by the magnetic energies), filled circles for the points of
    the first fit, filled squares for those of the second fit after a kink (Fig. 4.26: two
    curves for one run), open circles for the points in neither; each fitted parabola over
    its own points, both moduli in the legend."""
    if data.energy_density is None:
        return
    fig, ax = plt.subplots(figsize=(7.4, 5.0), layout="constrained")
    groups = data.field_groups()
    stress = run.run_type == "mess_stress"
    unit, scale = _modulus_unit(data)
    symbol = _modulus_symbol(data)
    unfitted = second_drawn = False
    for (k, steps), color in zip(groups, case_colors(len(groups))):
        x, u = data.strain[steps], data.energy_density[steps]
        a = data.modulus[k] if k < data.modulus.size else math.nan
        c = data.offset[k] if k < data.offset.size else math.nan
        fitted = fit_mask(x.size, data.first_point[k] if k < data.first_point.size else 0,
                          data.fit_points[k] if k < data.fit_points.size else -1)
        valid = bool(data.fit_valid[k]) if k < data.fit_valid.size else False
        fit_ok = not stress and valid and math.isfinite(a) and math.isfinite(c)
        second = not stress and data.second.ok(k)
        in_second = data.second.points(k, x.size) if second else np.zeros(x.size, dtype=bool)
        shift = c if fit_ok else np.nanmin(u)
        label = data.field_label(k)
        if fit_ok:
            label += f": {symbol} = {a / scale:.3g} {unit}"
        elif not stress:
            label += ": no valid fit"
        if second:
            label += f"; after the kink {data.second.modulus[k] / scale:.3g} {unit}"
        ax.plot(x[fitted], u[fitted] - shift, "o", color=color, markersize=4, label=label)
        if second:
            second_drawn = True
            ax.plot(x[in_second], u[in_second] - shift, "s", color=color, markersize=4)
            xs = np.linspace(np.min(x[in_second]), np.max(x[in_second]), 100)
            ax.plot(xs, data.second.curve(k, xs) - shift, "--", color=color, linewidth=1.0)
        rest = ~fitted & ~in_second
        if np.any(rest):
            unfitted = True
            ax.plot(x[rest], u[rest] - shift, "o", color=color, markersize=4,
                    markerfacecolor="none")
        if fit_ok and np.sum(fitted) >= 2:
            xs = np.linspace(np.min(x[fitted]), np.max(x[fitted]), 100)
            ax.plot(xs, 0.5 * a * xs**2, "-", color=color, linewidth=1.0)
    handles, labels = ax.get_legend_handles_labels()
    if unfitted:
        handles.append(Line2D([], [], color="0.3", marker="o", markerfacecolor="none",
                              linestyle="none"))
        labels.append("not fitted (zero strain above the next point,\nor after the kink)")
    if not stress:
        handles.append(Line2D([], [], color="0.3", marker="o", markersize=4))
        labels.append(r"fit $u = a x^2/2 + c$ and its points")
    if second_drawn:
        handles.append(Line2D([], [], color="0.3", linestyle="--", marker="s", markersize=4))
        labels.append(f"second fit after the kink,\n{data.second.formula()}, and its points")
    if len(labels) > 8:
        # Many fields (the helix has twelve): below the axes, which it would otherwise cover.
        legend_below(fig, handles, labels, per_row=2, fontsize=7, grow=True)
    else:
        ax.legend(handles, labels, fontsize=7, loc="upper left")
    ax.set_xlabel(strain_label(run, data))
    ax.set_ylabel(r"energy density $u - c$ (J/m$^3$)" if not stress
                  else r"energy density $u - u_{min}$ (J/m$^3$)")
    ax.axhline(0.0, color="0.8", linewidth=0.6, zorder=0)
    ax.grid(alpha=0.25)
    suptitle(run, fig)
    run.save(fig, "energy_density_fit.png")


def fit_mask(n, first, count):
    """The points of one field (n, in load order) that a fit used: `count` points from index
    `first` (count < 0: all from `first`; /analysis/fit_points = -1 in old files)."""
    first = max(int(first), 0)
    count = n - first if count < 0 else min(int(count), n - first)
    mask = np.zeros(n, dtype=bool)
    mask[first:first + max(count, 0)] = True
    return mask


class SecondFit:
    """The fit after a kink (/analysis/second_*, one entry per field; second_valid 0 and NaN
    where a field has no kink or too few points after it). Everything that depends on the
    fit's form is here: curve() and formula()."""

    def __init__(self, a, fields):
        self.present = a is not None and "second_modulus" in a
        nan = np.full(fields, math.nan)
        self.modulus = _array(a, "second_modulus", nan)
        self.offset = _array(a, "second_offset", nan)
        self.rms_residual = _array(a, "second_rms_residual", nan)
        self.first_point = _array(a, "second_first_point", np.zeros(fields)).astype(int)
        self.fit_points = _array(a, "second_fit_points", np.zeros(fields)).astype(int)
        self.valid = _array(a, "second_valid", np.zeros(fields)).astype(bool)
        # u = a x^2/2 + b x + c when the run stores b, else u = a x^2/2 + c.
        self.slope = _array(a, "second_slope", None)
        self.form = _text(a.attrs.get("second_form", "")) if a is not None else ""

    def ok(self, k):
        """Field k has a valid second fit with finite coefficients over at least 2 points."""
        if not self.present or k >= min(self.modulus.size, self.offset.size, self.valid.size,
                                         self.fit_points.size):
            return False
        return bool(self.valid[k]) and math.isfinite(self.modulus[k]) \
            and math.isfinite(self.offset[k]) and self.fit_points[k] >= 2 \
            and math.isfinite(self._b(k))

    def points(self, k, n):
        return fit_mask(n, self.first_point[k], self.fit_points[k])

    def _b(self, k):
        return float(self.slope[k]) if self.slope is not None and k < self.slope.size else 0.0

    def curve(self, k, x):
        """u(x) of field k's second fit, from the stored coefficients."""
        return 0.5 * self.modulus[k] * x**2 + self._b(k) * x + self.offset[k]

    def formula(self):
        if self.form:
            return self.form
        return r"$u = a x^2/2 + b x + c$" if self.slope is not None else r"$u = a x^2/2 + c$"


def stress_strain(run, data):
    """Stress runs: applied stress against measured strain per field, with the slope fitted
    through the origin (the modulus of /analysis)."""
    fig, ax = plt.subplots(figsize=(7.0, 4.8), layout="constrained")
    groups = data.field_groups()
    unit, scale = _modulus_unit(data)
    for (k, steps), color in zip(groups, case_colors(len(groups))):
        x, s = data.strain[steps], data.load_value[steps]
        a = data.modulus[k] if k < data.modulus.size else math.nan
        label = data.field_label(k)
        if k < data.fit_valid.size and data.fit_valid[k]:
            label += f": {_modulus_symbol(data)} = {a / scale:.3g} {unit}"
            xs = np.linspace(min(0.0, np.min(x)), max(0.0, np.max(x)), 50)
            ax.plot(xs, a * xs, "-", color=color, linewidth=1.0)
        else:
            label += ": no valid fit"
        ax.plot(x, s, "o", color=color, markersize=4, label=label)
    ax.set_xlabel(strain_label(run, data))
    ax.set_ylabel(f"applied stress ({data.load_unit or 'Pa'})")
    ax.grid(alpha=0.25)
    ax.legend(fontsize=7, loc="best")
    suptitle(run, fig)
    run.save(fig, "stress_strain.png")


def strain_label(run, data):
    if run.run_type == "mess_stress" and data.modulus_name.startswith("E_eff"):
        return STRAIN_LABELS["E_eff (stress)"]
    return STRAIN_LABELS.get(data.modulus_name, "strain")


def _modulus_symbol(data):
    return MODULUS_LABELS.get(data.modulus_name, (data.modulus_name, ""))[0]


def _modulus_unit(data):
    return MODULUS_LABELS.get(data.modulus_name, ("", "kPa"))[1], 1e3


INVALID_FIT_LABEL = "invalid fit, not a result"
INVALID_COLOR = "0.6"


def modulus(run, data):
    """Fig. 4.18: the effective modulus against |B|. Invalid fits (too few points, an
    unconverged step, wrong curvature; /analysis/valid = 0) are drawn hollow and grey, apart
    from the line through the valid ones. Fields with a valid second fit after a kink add its
    modulus as a second series (Fig. 4.25 lists such a run twice)."""
    unit, scale = _modulus_unit(data)
    fig, ax = plt.subplots(figsize=(6.4, 4.8), layout="constrained")
    b_mt = data.field_magnitude * 1e3
    ok = data.fit_valid
    ax.plot(b_mt[ok], data.modulus[ok] / scale, "o-", color="C0", markersize=5,
            label=_modulus_symbol(data) + (" (first fit)" if data.second.present else ""))
    second = np.array([data.second.ok(k) for k in range(b_mt.size)], dtype=bool)
    if np.any(second):
        ax.plot(b_mt[second], data.second.modulus[second] / scale, "D", linestyle="none",
                color="C1", markersize=5, label=_modulus_symbol(data) + " after the kink")
        ax.legend(fontsize=8, loc="best")
    _draw_invalid(ax, b_mt, data.modulus / scale, ok)
    _note_missing(ax, b_mt, ok, "no valid fit")
    ax.set_xlabel(ABS_FIELD_LABEL)
    ax.set_ylabel(f"{_modulus_symbol(data)} ({unit})")
    ax.grid(alpha=0.25)
    suptitle(run, fig)
    run.save(fig, "modulus.png")


def mr_effect(run, data):
    """(modulus / modulus at the first field - 1) x 100 % against |B| (Section 4.3); values
    from an invalid fit (here or at the first field) hollow and grey."""
    fig, ax = plt.subplots(figsize=(6.4, 4.8), layout="constrained")
    b_mt = data.field_magnitude * 1e3
    ok = data.mr_valid
    ax.plot(b_mt[ok], data.mr_effect[ok], "s-", color="C3", markersize=5, label="MR effect")
    _draw_invalid(ax, b_mt, data.mr_effect, ok, marker="s")
    _note_missing(ax, b_mt, ok, "undefined (no valid modulus here or at the first field)")
    ax.axhline(0.0, color="0.6", linewidth=0.8, zorder=0)
    ax.set_xlabel(ABS_FIELD_LABEL)
    ax.set_ylabel(f"MR effect of {_modulus_symbol(data)} (%)")
    ax.grid(alpha=0.25)
    suptitle(run, fig)
    run.save(fig, "mr_effect.png")


def _draw_invalid(ax, x, y, ok, marker="o"):
    """The finite values of invalid fits: hollow grey markers, no line, one legend entry."""
    shown = ~ok & np.isfinite(y) & np.isfinite(x)
    if np.any(shown):
        ax.plot(x[shown], y[shown], marker, linestyle="none", color=INVALID_COLOR,
                markerfacecolor="none", markersize=6, label=INVALID_FIT_LABEL)
        ax.legend(fontsize=8, loc="best")


def _note_missing(ax, b_mt, ok, why):
    if not np.any(ok):
        finite = b_mt[np.isfinite(b_mt)]
        if finite.size and np.ptp(finite) > 0:
            ax.set_xlim(finite.min(), finite.max())
        ax.text(0.5, 0.5, why, transform=ax.transAxes, ha="center", va="center", color="0.4")
    elif not np.all(ok):
        ax.text(0.02, 0.02, f"{int(np.sum(~ok))} field(s) without a valid value: {why}",
                transform=ax.transAxes, fontsize=8, color="0.4")


# ---------------------------------------------------------------- configuration figures

def particle_magnetization(run, data):
    """Fig. 4.22: the particles at the last step with their magnetization, in 3D and projected
    on the x-z plane; arrow length M/Ms x 2R (a saturated particle's arrow spans a diameter)."""
    if data.centres is None or data.magnetization is None or data.centres.ndim != 3 \
            or data.centres.shape[1] == 0:
        return
    c = data.centres[-1] * 1e6
    m = data.magnetization[-1] / data.ms
    radius = data.radius * 1e6 if math.isfinite(data.radius) else 1.0
    arrows = m * 2.0 * radius
    fig = plt.figure(figsize=(10.0, 5.2), layout="constrained")
    ax3 = fig.add_subplot(1, 2, 1, projection="3d")
    ax3.scatter(c[:, 0], c[:, 1], c[:, 2], s=60, color="0.6", depthshade=False)
    ax3.quiver(c[:, 0], c[:, 1], c[:, 2], arrows[:, 0], arrows[:, 1], arrows[:, 2],
               color="C3", linewidth=1.5, arrow_length_ratio=0.3)
    ax3.set_xlabel(f"$x$ {UM_PAREN}")
    ax3.set_ylabel(f"$y$ {UM_PAREN}")
    ax3.set_zlabel(f"$z$ {UM_PAREN}")
    if data.box is not None and data.box.size == 3:
        lengths = data.box * 1e6
        ax3.set_xlim(0, lengths[0])
        ax3.set_ylim(0, lengths[1])
        ax3.set_zlim(0, lengths[2])
        try:
            ax3.set_box_aspect(lengths)
        except (AttributeError, ValueError):
            pass

    ax = fig.add_subplot(1, 2, 2)
    for p in range(c.shape[0]):
        ax.add_patch(Circle((c[p, 0], c[p, 2]), radius, facecolor="0.85", edgecolor="0.4",
                            linewidth=0.8))
    ax.quiver(c[:, 0], c[:, 2], arrows[:, 0], arrows[:, 2], angles="xy", scale_units="xy",
              scale=1.0, color="C3", width=0.006, zorder=3)
    if data.box is not None and data.box.size == 3:
        lx, lz = data.box[0] * 1e6, data.box[2] * 1e6
        ax.plot([0, lx, lx, 0, 0], [0, 0, lz, lz, 0], color="0.5", linestyle="--", linewidth=0.8,
                label="initial box")
        ax.legend(fontsize=8, loc="upper right")
    pad = 2.5 * radius
    low = [c[:, 0].min() - pad, c[:, 2].min() - pad]
    high = [c[:, 0].max() + pad, c[:, 2].max() + pad]
    if data.box is not None and data.box.size == 3:
        margin = 0.03 * max(data.box[0], data.box[2]) * 1e6
        low = [min(low[0], -margin), min(low[1], -margin)]
        high = [max(high[0], data.box[0] * 1e6 + margin), max(high[1], data.box[2] * 1e6 + margin)]
    ax.set_xlim(low[0], high[0])
    ax.set_ylim(low[1], high[1])
    ax.set_aspect("equal")
    ax.set_xlabel(f"$x$ {UM_PAREN}")
    ax.set_ylabel(f"$z$ {UM_PAREN}")
    ax.grid(alpha=0.25)
    b = data.field[-1]
    mean_m = np.mean(np.linalg.norm(m, axis=1))
    text = f"last step: |B| = {np.linalg.norm(b) * 1e3:.4g} mT"
    if np.linalg.norm(b) > 0:
        theta, phi = _angles(b)
        text += rf" ($\theta$ = {theta:.0f}°, $\varphi$ = {phi:.0f}°)"
    text += rf", mean $|M|/M_s$ = {mean_m:.3g}; arrows $2R\,M/M_s$"
    fig.suptitle((typeset(run.title) + "\n" if run.title else "") + text, fontsize=10)
    run.save(fig, "particle_magnetization.png")
