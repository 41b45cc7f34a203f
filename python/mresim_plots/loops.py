"""Drawing hysteresis loops branch by branch (shared by the loop-type run types)."""

import numpy as np
from matplotlib.lines import Line2D

from .common import BRANCH_LINESTYLE, BRANCH_STYLE

# The contact line of separation plots (S = 2R): behind the data (zorder 1; lines and markers
# are drawn at 2), thin, dash-dotted (the critical-field lines are dashed) and light, so that
# the markers of a pair in contact, which lie on it, stay visible.
CONTACT_STYLE = dict(color="0.6", linestyle="-.", linewidth=0.8, zorder=1)


def branch_segments(field, branch, values):
    """Yield (branch, x, y) per branch; each segment starts at the previous branch's last
    point so the drawn loop has no gaps at the turning points."""
    branch = np.asarray(branch).astype(int)
    for b in np.unique(branch):
        idx = np.flatnonzero(branch == b)
        if idx.size == 0:
            continue
        if idx[0] > 0:
            idx = np.concatenate(([idx[0] - 1], idx))
        yield b, np.asarray(field)[idx], np.asarray(values)[idx]


def draw_loop(ax, field, branch, values, color=None, linewidth=1.6, label_branches=True):
    """Draw one loop: Fig. 2.2 branch colours when color is None, else the given colour with
    the branch shown by the line style."""
    for b, x, y in branch_segments(field, branch, values):
        if color is None:
            style = dict(BRANCH_STYLE.get(b, dict(color="k", linestyle="-", label=f"branch {b}")))
            if not label_branches:
                style.pop("label")
        else:
            style = dict(color=color, linestyle=BRANCH_LINESTYLE.get(b, "-"))
        ax.plot(x, y, linewidth=linewidth, **style)


def branch_style_legend(ax, branches, loc="lower right"):
    """A legend of line styles (one per branch) for plots coloured by case."""
    handles = [Line2D([], [], color="0.3", linestyle=BRANCH_LINESTYLE.get(b, "-"),
                      label=BRANCH_STYLE.get(b, {}).get("label", f"branch {b}"))
               for b in sorted(set(int(b) for b in branches))]
    return ax.legend(handles=handles, loc=loc, fontsize=8, title="branch", title_fontsize=8)


def critical_field_lines(ax, hc1, hc2, color=None, with_labels=True, alpha=1.0, shade=True):
    """Dashed vertical lines at +-mu0 H_C1 and +-mu0 H_C2 (in T, as the field axis) and, when
    shade, the bistable field ranges H_C1 < |B| < H_C2 in light grey (Figs. 2.2, 3.13)."""
    specs = [(hc1, "0.45", r"$\pm\mu_0 H_{C1}$"), (hc2, "0.1", r"$\pm\mu_0 H_{C2}$")]
    for value, default_color, name in specs:
        label = f"{name} = {value:.3g} T" if with_labels else None
        for sign in (1.0, -1.0):
            ax.axvline(sign * value, color=color or default_color, linestyle="--",
                       linewidth=0.9, alpha=alpha, zorder=1, label=label if sign > 0 else None)
    if shade:
        for sign, label in ((1.0, "bistable range" if with_labels else None), (-1.0, None)):
            ax.axvspan(sign * hc1, sign * hc2, color="0.5", alpha=0.1, linewidth=0, zorder=0,
                       label=label)
