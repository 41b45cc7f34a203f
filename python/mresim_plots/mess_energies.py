"""Energies by term of the 3D runs (Figs. 4.14-4.17 a-f).

  energies.png            every run: each term against the field; hysteresis and
                          magnetostriction runs along the loop (B along the field direction),
                          strain and stress runs at zero load of each field (against |B|)
  energies_vs_strain.png  strain and stress runs: per field, the change of each term from its
                          zero-load value against the measured strain, E(x) - E(x=0) at that
                          field (Figs. 4.14-4.17 a-f: the strain dependence, which the field
                          dependence would swamp on a common axis)

Terms that are zero at every step (e.g. WCA without contact, dipole-dipole with one particle,
the load term of a strain run) or, in energies_vs_strain.png, that do not change with the
strain, get no panel; a note under the panels names them.
"""

import math
from collections import namedtuple

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.lines import Line2D

from .common import case_colors, legend_below
from .typography import suptitle
from .mess import (ABS_FIELD_LABEL, ENERGY_PANELS, FIELD_MT_LABEL, draw_legs,
                   leg_legend_handles, legs, strain_label)

# A term is left out when its largest |value| (energies.png) or |change| (energies_vs_strain.png)
# is at most this fraction of the largest one among the panels: zero up to rounding. The terms
# this is for are exactly zero (WCA beyond the cut-off, no second particle, no load).
ZERO_RTOL = 1e-9
LINEARIZED = "self_linearized"  # eq. 4.73, reported only: dashed in the self panel

# One field of a strain or stress run: its field index, its steps in load order, the zero-load
# step (the reference), the measured strain per step and {term: E - E(reference)} per step.
FieldChanges = namedtuple("FieldChanges", "field steps reference strain changes")


def energy_panels(data):
    """(dataset, panel title) in the system's term order, then the total."""
    fallback = dict(ENERGY_PANELS)
    order = data.energy_order or [name for name, _ in ENERGY_PANELS if name != "total"]
    panels = [(name, data.energy_titles.get(name, fallback.get(name, name))) for name in order
              if name in data.energies and name != LINEARIZED]
    if "total" in data.energies:
        panels.append(("total", "total"))
    return panels


def nonzero_panels(panels, values):
    """(kept, left out): the panels whose values ({name: array}) are not zero everywhere, in
    the given order, and the titles of the others (ZERO_RTOL of the largest |value|)."""
    largest = {name: _max_abs(values[name]) for name, _ in panels}
    scale = max(largest.values(), default=0.0)
    kept = [(n, t) for n, t in panels if scale > 0 and largest[n] > ZERO_RTOL * scale]
    left_out = [t for n, t in panels if (n, t) not in kept]
    return kept, left_out


def _max_abs(values):
    finite = np.abs(np.asarray(values, dtype=float))
    finite = finite[np.isfinite(finite)]
    return float(finite.max()) if finite.size else 0.0


def reference_step(data, steps):
    """The zero-load step of a field: the smallest |load value| (the first one on a tie)."""
    load = np.abs(np.asarray(data.load_value[steps], dtype=float))
    return int(steps[np.argmin(np.where(np.isfinite(load), load, np.inf))])


def strain_changes(data):
    """FieldChanges per field of a strain or stress run (NaN where a step is NaN)."""
    out = []
    for k, steps in data.field_groups():
        steps = steps[np.argsort(data.load_index[steps], kind="stable")]
        ref = reference_step(data, steps)
        changes = {name: e[steps] - e[ref] for name, e in data.energies.items()}
        out.append(FieldChanges(int(k), steps, ref, data.strain[steps], changes))
    return out


def energies(run, data):
    """energies.png: against B along the loop (field sweeps) or at zero load against |B|
    (strain and stress runs)."""
    if data.load_run:
        refs = [reference_step(data, steps) for _, steps in data.field_groups()]
        refs = np.asarray(sorted(refs, key=lambda s: np.linalg.norm(data.field[s])), dtype=int)
        values = {name: e[refs] for name, e in data.energies.items()}
    else:
        values = data.energies
    panels, left_out = nonzero_panels(energy_panels(data), values)
    if not panels:
        return
    fig, axes = _grid(len(panels))
    handles = []
    if data.load_run:
        b_mt = np.linalg.norm(data.field[refs], axis=1) * 1e3
        for ax, (name, _) in zip(axes.flat, panels):
            ax.plot(b_mt, values[name], "o-", color="C0", markersize=3, linewidth=1.2)
            if name == "self" and LINEARIZED in values:
                ax.plot(b_mt, values[LINEARIZED], "--", color="C1", linewidth=1.0)
        xlabel = ABS_FIELD_LABEL + ", at zero " + _load_word(run)
    else:
        b_mt = data.b_along * 1e3
        leg = legs(data.b_along)
        for ax, (name, _) in zip(axes.flat, panels):
            draw_legs(ax, b_mt, leg, values[name], "C0", marker="o")
            if name == "self" and LINEARIZED in values:
                draw_legs(ax, b_mt, leg, values[LINEARIZED], "C1")
        if np.unique(leg).size > 1:
            handles = leg_legend_handles(b_mt, leg)
        xlabel = FIELD_MT_LABEL
    if any(name == "self" for name, _ in panels) and LINEARIZED in values:
        handles.append(Line2D([], [], color="C1", linestyle="--",
                              label="self: linearized, eq. 4.73 (reported only)"))
    _finish(run, fig, axes, panels, xlabel, "energy (J)", handles,
            _note("zero throughout", left_out))
    run.save(fig, "energies.png")


def energies_vs_strain(run, data):
    """energies_vs_strain.png (Figs. 4.14-4.17 a-f): per field (a colour each), the change of
    each term from its zero-load value against the measured strain."""
    fields = strain_changes(data)
    if not fields or max(f.steps.size for f in fields) < 2:
        return
    values = {name: np.concatenate([f.changes[name] for f in fields]) for name in data.energies}
    panels, left_out = nonzero_panels(energy_panels(data), values)
    if not panels:
        return
    fig, axes = _grid(len(panels))
    colors = case_colors(len(fields))
    for ax, (name, _) in zip(axes.flat, panels):
        for f, color in zip(fields, colors):
            ax.plot(f.strain, f.changes[name], "o-", color=color, markersize=3, linewidth=1.0)
            if name == "self" and LINEARIZED in f.changes:
                ax.plot(f.strain, f.changes[LINEARIZED], "--", color=color, linewidth=0.8)
        ax.axhline(0.0, color="0.8", linewidth=0.6, zorder=0)
    handles = [Line2D([], [], color=c, marker="o", markersize=3, label=data.field_label(f.field))
               for f, c in zip(fields, colors)]
    if any(name == "self" for name, _ in panels) and LINEARIZED in data.energies:
        handles.append(Line2D([], [], color="0.3", linestyle="--",
                              label="self: linearized, eq. 4.73 (reported only)"))
    word = _load_word(run)
    _finish(run, fig, axes, panels, strain_label(run, data), rf"$E - E$(zero {word}) (J)",
            handles, _note(f"no change with the {word}", left_out))
    run.save(fig, "energies_vs_strain.png")


def _load_word(run):
    return "stress" if run.run_type == "mess_stress" else "strain"


def _note(why, left_out):
    return f"not drawn ({why}): {', '.join(left_out)}" if left_out else ""


def _grid(n):
    ncols = 4 if n > 6 else min(n, 3)
    nrows = math.ceil(n / ncols)
    return plt.subplots(nrows, ncols, squeeze=False, sharex=True,
                        figsize=(3.3 * max(ncols, 2) + 0.4, 2.6 * nrows + 1.0),
                        layout="constrained")


def _finish(run, fig, axes, panels, xlabel, ylabel, handles, note):
    ncols = axes.shape[1]
    for ax, (_, title) in zip(axes.flat, panels):
        ax.set_title(title, fontsize=9, loc="right")  # the y offset text is left
        ax.grid(alpha=0.25)
        ax.ticklabel_format(axis="y", style="sci", scilimits=(-2, 3), useMathText=True)
        ax.tick_params(labelsize=8)
    for ax in axes.flat[len(panels):]:
        ax.set_visible(False)
    for ax in axes[:, 0]:
        ax.set_ylabel(ylabel)
    for i, ax in enumerate(axes.flat[:len(panels)]):
        if i + ncols >= len(panels):
            ax.set_xlabel(xlabel)
            ax.xaxis.set_tick_params(labelbottom=True)
    _figure_legend(fig, handles, note)
    suptitle(run, fig)


def _figure_legend(fig, handles, note=""):
    """The legend and the note in a strip below the axes, four entries per row."""
    if not handles and not note:
        return
    per_row = min(max(len(handles), 1), 4)
    legend_below(fig, handles, [h.get_label() for h in handles], per_row, note)
