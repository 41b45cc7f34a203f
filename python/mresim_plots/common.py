"""Shared helpers: reading a run directory, styles, saving figures."""

import csv
import math
import os
import tomllib

import h5py
import matplotlib

matplotlib.use("Agg")  # figures are files; never open a display
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from .typography import typeset  # noqa: E402

DPI = 150
DEFAULT_RADIUS_M = 1.5e-6
TAUPE = "#b9a281"  # "no hysteresis" cells, as in Figs. 2.5 and 2.9

# Branch colours of Fig. 2.2: 0 -> +Bmax magenta, descent cyan, final rise blue dashed.
BRANCH_STYLE = {
    0: dict(color="#d81bd8", linestyle="-", label="initial rise"),
    1: dict(color="#00b3c7", linestyle="-", label="descent"),
    2: dict(color="#1f3fd6", linestyle="--", label="final rise"),
}
# With several cases the colour is the case's; the branch shows in the line style.
BRANCH_LINESTYLE = {0: ":", 1: "-", 2: "--"}
FIELD_LABEL = r"$B = \mu_0 H$ (T)"
MAG_LABEL = r"$M/M_s$"
# Run.options: the view options of `mresim plot DIR` (mresim_plots/view_options.py parses
# them); these defaults mean "none given".
PLOT_OPTION_DEFAULTS = dict(step=[], plane=[], particle=None, field_map=[], animate=False)


class PlotError(Exception):
    """A problem with the run directory, reported as one line."""


def legend_below(fig, handles, labels, per_row, note="", fontsize=8, grow=False):
    """A figure legend (and a grey note under it) in a strip kept free below the axes, for
    legends too long to sit on an axes without covering the data (matplotlib 3.6, Debian 12,
    has no loc="outside ..."). With grow the figure gets taller by the strip, so the axes keep
    their size."""
    rows = (math.ceil(len(labels) / per_row) if labels else 0) + (1 if note else 0)
    strip_inches = 0.1 + 0.22 * rows
    if grow:
        fig.set_figheight(fig.get_figheight() + strip_inches)
    height = fig.get_figheight()
    strip = strip_inches / height
    fig.get_layout_engine().set(rect=(0.0, strip, 1.0, 1.0 - strip))
    if labels:
        fig.legend(handles, labels, loc="lower center", ncol=per_row, fontsize=fontsize,
                   frameon=False, bbox_to_anchor=(0.5, 0.2 / height if note else 0.0))
    if note:
        fig.text(0.5, 0.04 / height, note, ha="center", va="bottom", fontsize=fontsize,
                 color="0.35")


def case_colors(n):
    """n distinguishable colours (tab10, then a sampled colormap beyond ten)."""
    if n <= 10:
        return [plt.get_cmap("tab10")(i) for i in range(n)]
    return [plt.get_cmap("viridis")(x) for x in np.linspace(0.0, 0.9, n)]


class Run:
    """A finished run directory: results.h5 attributes, the input TOML, its CSV tables."""

    def __init__(self, directory, options=None):
        self.dir = directory
        self.options = {**PLOT_OPTION_DEFAULTS, **(options or {})}
        self.h5_path = os.path.join(directory, "results.h5")
        if not os.path.isfile(self.h5_path):
            raise PlotError(f"'{directory}' has no results.h5")
        try:
            with h5py.File(self.h5_path, "r") as f:
                self.attrs = {k: _text(v) for k, v in f.attrs.items()}
        except OSError as e:
            raise PlotError(f"cannot read {self.h5_path}: {e}") from None
        self.run_type = self.attrs.get("run_type", "")
        self.config = _parse_toml(self.attrs.get("input_toml", ""))
        run_table = self.config.get("run", {})
        self.title = run_table.get("title") or self.attrs.get("title") or ""
        self.figures_dir = os.path.join(directory, "figures")
        self.written = []

    def h5(self):
        return h5py.File(self.h5_path, "r")

    def path(self, name):
        return os.path.join(self.dir, name)

    def has(self, name):
        return os.path.isfile(self.path(name))

    def table(self, name):
        """CSV as {column: array}; numeric columns become float arrays, others str arrays."""
        path = self.path(name)
        if not os.path.isfile(path):
            raise PlotError(f"'{self.dir}' has no {name}")
        with open(path, newline="") as fh:
            reader = csv.DictReader(fh)
            if reader.fieldnames is None:
                raise PlotError(f"{path} is empty")
            rows = list(reader)
            columns = {name: [r[name] for r in rows] for name in reader.fieldnames}
        return {k: _column(v) for k, v in columns.items()}

    def optional_table(self, name):
        return self.table(name) if self.has(name) else None

    def radius(self, case_index=None):
        """Sphere radius (m): the case's [[case]] material.radius, else [material].radius."""
        radius = self.config.get("material", {}).get("radius", DEFAULT_RADIUS_M)
        cases = self.config.get("case", [])
        if case_index is not None and case_index < len(cases):
            radius = cases[case_index].get("material", {}).get("radius", radius)
        return float(radius)

    def save(self, fig, name):
        os.makedirs(self.figures_dir, exist_ok=True)
        path = os.path.join(self.figures_dir, name)
        fig.savefig(path, dpi=DPI)
        plt.close(fig)
        self.written.append(path)
        return path

    def suptitle(self, fig):
        if self.title:
            fig.suptitle(typeset(self.title), fontsize=11)


def require(table, columns, name):
    missing = [c for c in columns if c not in table]
    if missing:
        raise PlotError(f"{name} lacks column(s) {', '.join(missing)}")


def _text(value):
    if isinstance(value, bytes):
        return value.decode("utf-8", "replace")
    if isinstance(value, np.ndarray) and value.shape == ():
        return value.item()
    return value


def _parse_toml(text):
    try:
        return tomllib.loads(text) if text else {}
    except tomllib.TOMLDecodeError:
        return {}  # titles and radii are cosmetic: fall back to defaults


def _column(values):
    try:
        return np.array([float(v) for v in values], dtype=float)
    except ValueError:
        return np.array(values, dtype=str)
