"""magnetostriction.png: the strain of the free box along the field against B
(/steps/magnetostriction; mess_magnetostriction and field sweeps with a free face), drawn
leg by leg as separation_magnetization.png. Skipped when the dataset is absent, or zero or
NaN at every step (a box held on all faces)."""

import numpy as np
from matplotlib import pyplot as plt
from matplotlib.lines import Line2D

from .mess import FIELD_MT_LABEL, draw_legs, leg_legend_handles, legs
from .typography import suptitle

COLOR = "#2a9d3a"
LABEL = r"magnetostriction $\varepsilon_\parallel$ (box strain along $B$)"


def has_magnetostriction(data):
    m = data.magnetostriction
    return m is not None and m.shape == data.b_along.shape and np.any(np.isfinite(m) & (m != 0))


def magnetostriction(run, data):
    if not has_magnetostriction(data):
        return
    b_mt = data.b_along * 1e3
    leg = legs(data.b_along)
    fig, ax = plt.subplots(figsize=(7.0, 4.8), layout="constrained")
    ax.axhline(0.0, color="0.75", linewidth=0.7, zorder=0)
    ax.axvline(0.0, color="0.8", linewidth=0.6, zorder=0)
    draw_legs(ax, b_mt, leg, data.magnetostriction, COLOR, marker="o")
    ax.ticklabel_format(axis="y", style="sci", scilimits=(-2, 3), useMathText=True)
    ax.set_xlabel(FIELD_MT_LABEL)
    ax.set_ylabel(LABEL)
    ax.grid(alpha=0.25)
    handles = [Line2D([], [], color=COLOR, marker="o", markersize=3,
                      label=r"$\varepsilon_\parallel$")]
    if np.unique(leg).size > 1:
        handles += leg_legend_handles(b_mt, leg)
    ax.legend(handles=handles, fontsize=8, loc="best")
    suptitle(run, fig)
    run.save(fig, "magnetostriction.png")
