"""Cross-run figures of a sweep directory (`mresim plot SWEEPDIR`, docs/sweeps.md), drawn from
the collected tables of `mresim collect` (SWEEPDIR/collected.h5):

    sweep_modulus.png     the effective modulus against |B|, one curve per point
                          (Figs. 4.18, 4.21, 4.25: several runs on one plot)
    sweep_mr_effect.png   the MR effect against the swept parameter (Fig. 4.19): with one
                          swept key one curve per non-zero field, with several the largest
                          field's, one curve per combination of the other keys

Both need the modulus table of strain or stress runs; points that are not finished are left
out (and counted in the title), invalid fits are drawn hollow and grey as in the run figures.
"""

import os

import h5py
import matplotlib.pyplot as plt
import numpy as np

from .common import DPI, PlotError, case_colors
from .typography import typeset

COLLECTED = "collected.h5"
# The modulus column of modulus.csv, its symbol and how it is shown.
MODULI = (("G_eff_Pa", r"$G_\mathrm{eff}$", "kPa", 1e3),
          ("E_eff_Pa", r"$E_\mathrm{eff}$", "kPa", 1e3),
          ("torsion_stiffness_J_m3", "torsion stiffness", r"kJ/m$^3$", 1e3))
ABS_FIELD_LABEL = r"$|B|$ (mT)"
INVALID_COLOR = "0.6"


def _text(value):
    return value.decode("utf-8", "replace") if isinstance(value, bytes) else value


class Sweep:
    """A sweep directory's collected tables: {group: {column: array}} and the swept keys."""

    def __init__(self, directory):
        self.dir = directory
        self.h5_path = os.path.join(directory, COLLECTED)
        if not os.path.isfile(self.h5_path):
            raise PlotError(f"'{directory}' has no {COLLECTED}; run 'mresim collect {directory}' "
                            "first")
        self.tables = {}
        with h5py.File(self.h5_path, "r") as f:
            keys = _text(f.attrs.get("parameters", ""))
            self.keys = [k for k in keys.split("\n") if k]
            for name, group in f.items():
                self.tables[name] = {c: _column(group[c][()]) for c in group}
        self.figures_dir = os.path.join(directory, "figures")
        self.written = []

    def table(self, name):
        if name not in self.tables:
            raise PlotError(f"{self.h5_path} has no table '{name}'")
        return self.tables[name]

    def save(self, fig, name):
        os.makedirs(self.figures_dir, exist_ok=True)
        path = os.path.join(self.figures_dir, name)
        fig.savefig(path, dpi=DPI)
        plt.close(fig)
        self.written.append(path)


def _column(values):
    if values.dtype.kind in "SO":
        return np.array([_text(v) for v in values], dtype=str)
    return np.asarray(values)


def _label(table, row, keys):
    return ", ".join(f"{k} = {table[k][row]}" for k in keys)


def _varying(table, keys):
    return [k for k in keys if len(set(np.asarray(table[k]).tolist())) > 1]


def plot(sweep):
    if "modulus" not in sweep.tables:
        raise PlotError(f"no cross-run figures for '{sweep.dir}': its points wrote no modulus "
                        "table (strain and stress runs do); the collected tables are "
                        f"{os.path.join(sweep.dir, 'collected_*.csv')}")
    table = sweep.table("modulus")
    modulus = next((m for m in MODULI if m[0] in table), None)
    if modulus is None:
        raise PlotError(f"{sweep.h5_path}: the modulus table has none of the columns "
                        f"{', '.join(m[0] for m in MODULI)}")
    points = sweep.table("points")
    unfinished = int(np.sum(~np.isin(points["status"], ("finished", "invalid_results"))))
    modulus_against_field(sweep, table, modulus, unfinished)
    mr_effect_against_parameter(sweep, table, unfinished)


def _title(fig, sweep, unfinished):
    text = f"sweep {os.path.basename(os.path.normpath(sweep.dir))}"
    if unfinished:
        text += f" ({unfinished} point(s) not finished, not shown)"
    fig.suptitle(typeset(text), fontsize=11)


def _finished_rows(table):
    return np.isin(table["status"], ("finished", "invalid_results")) & np.isfinite(table["B_T"])


def modulus_against_field(sweep, table, modulus, unfinished):
    column, symbol, unit, scale = modulus
    rows = _finished_rows(table)
    point_ids = sorted(set(table["point"][rows].astype(int).tolist()))
    keys = _varying(table, sweep.keys) or sweep.keys
    fig, ax = plt.subplots(figsize=(7.2, 5.0), layout="constrained")
    colors = case_colors(max(len(point_ids), 1))
    for color, point in zip(colors, point_ids):
        mine = rows & (table["point"] == point)
        b_mt = np.abs(table["B_T"][mine]) * 1e3
        value = table[column][mine] / scale
        ok = table["valid"][mine] == 1 if "valid" in table else np.ones(b_mt.size, dtype=bool)
        first = int(np.flatnonzero(mine)[0])
        ax.plot(b_mt[ok], value[ok], "o-", color=color, markersize=4,
                label=typeset(_label(table, first, keys)))
        shown = ~ok & np.isfinite(value)
        ax.plot(b_mt[shown], value[shown], "o", markerfacecolor="none", color=INVALID_COLOR)
    ax.set_xlabel(ABS_FIELD_LABEL)
    ax.set_ylabel(f"{symbol} ({unit})")
    ax.grid(alpha=0.25)
    if point_ids:
        ax.legend(fontsize=7, loc="best")
    _title(fig, sweep, unfinished)
    sweep.save(fig, "sweep_modulus.png")


def mr_effect_against_parameter(sweep, table, unfinished):
    rows = _finished_rows(table) & (table["mr_effect_valid"] == 1)
    varying = _varying(table, sweep.keys)
    numeric = [k for k in varying if table[k].dtype.kind == "f"]
    fig, ax = plt.subplots(figsize=(7.2, 5.0), layout="constrained")
    field = np.round(np.abs(table["B_T"]), 12)
    if not numeric:
        x_key = None
        x = table["point"].astype(float)
    else:
        x_key = numeric[0]
        x = table[x_key]
    others = [k for k in varying if k != x_key]
    if not others:
        # One swept key: a curve per non-zero field.
        series = [(f"|B| = {b * 1e3:g} mT", rows & (field == b))
                  for b in sorted(set(field[rows].tolist())) if b > 0]
    else:
        # Several: the largest field of each point, a curve per combination of the others.
        top = np.zeros(field.size, dtype=bool)
        for point in set(table["point"][rows].astype(int).tolist()):
            mine = rows & (table["point"] == point)
            top |= mine & (field == field[mine].max())
        combos = sorted({tuple(table[k][i] for k in others) for i in np.flatnonzero(top)})
        series = []
        for combo in combos:
            match = top.copy()
            for k, v in zip(others, combo):
                match &= table[k] == v
            series.append((", ".join(f"{k} = {v}" for k, v in zip(others, combo)), match))
    for color, (label, match) in zip(case_colors(max(len(series), 1)), series):
        order = np.argsort(x[match], kind="stable")
        ax.plot(x[match][order], table["mr_effect_percent"][match][order], "s-", color=color,
                markersize=5, label=typeset(label))
    ax.axhline(0.0, color="0.6", linewidth=0.8, zorder=0)
    ax.set_xlabel(x_key if x_key else "sweep point")
    ax.set_ylabel("MR effect (%)")
    ax.grid(alpha=0.25)
    if series:
        ax.legend(fontsize=8, loc="best")
    _title(fig, sweep, unfinished)
    sweep.save(fig, "sweep_mr_effect.png")
