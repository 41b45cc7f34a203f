"""froehlich_kennelly and preisach: the magnetization curve of one material (Figs. 1.5, 1.6)."""

import math

import matplotlib.pyplot as plt
import numpy as np

from .common import BRANCH_STYLE, FIELD_LABEL, MAG_LABEL, PlotError, require
from .loops import branch_segments, draw_loop
from .typography import suptitle

# Where each leg's number goes: (field as a fraction of B_max, offset in points), for an open
# loop (Fig. 1.5) and for one whose legs coincide (Fig. 1.6).
NUMBER_SPOTS = {0: (0.3, (-12, 12)), 1: (-0.55, (-14, 12)), 2: (0.55, (14, -12))}
COINCIDENT_SPOTS = {0: (0.15, (14, -14)), 1: (-0.5, (-14, 12)), 2: (0.6, (14, -14))}


def plot(run):
    table = run.table("summary.csv")
    require(table, ["branch", "B_T", "M_over_Ms"], "summary.csv")
    if table["B_T"].size == 0:
        raise PlotError(f"{run.path('summary.csv')} has no rows")
    field, branch, m = table["B_T"], table["branch"].astype(int), table["M_over_Ms"]
    attrs = curve_attributes(run)

    fig, ax = plt.subplots(figsize=(6.4, 4.8), layout="constrained")
    for sign in (1.0, -1.0):
        ax.axhline(sign, color="0.55", linestyle=":", linewidth=1.0)
    ax.axhline(0.0, color="0.8", linewidth=0.6)
    ax.axvline(0.0, color="0.8", linewidth=0.6)
    draw_loop(ax, field, branch, m, label_branches=False)
    number_legs(ax, field, branch, m)
    ax.annotate(r"$M_s$", xy=(field.min(), 1.0), xytext=(4, 3), textcoords="offset points",
                fontsize=10, color="0.3")
    mark_loop_features(ax, attrs)
    ax.set_xlabel(FIELD_LABEL)
    ax.set_ylabel(MAG_LABEL)
    ax.set_ylim(-1.15, 1.15)
    ax.grid(alpha=0.25)
    handles = [plt.Line2D([], [], color=s["color"], linestyle=s["linestyle"],
                          label=f"{b + 1}: {s['label']}")
               for b, s in BRANCH_STYLE.items() if np.any(branch == b)]
    ax.legend(handles=handles, loc="lower right", fontsize=8)
    describe_material(ax, attrs)
    suptitle(run, fig)
    run.save(fig, "magnetization.png")


def curve_attributes(run):
    with run.h5() as f:
        return {k: float(v) for k, v in f["curve"].attrs.items()} if "curve" in f else {}


def number_legs(ax, field, branch, m):
    """Label the legs 1, 2, 3 as Fig. 1.5 does."""
    b_max = np.max(np.abs(field))
    spots = COINCIDENT_SPOTS if loop_width(field, branch, m) < 1e-3 else NUMBER_SPOTS
    for b, x, y in branch_segments(field, branch, m):
        spot = spots.get(b)
        if spot is None or x.size == 0:
            continue
        i = int(np.argmin(np.abs(x - spot[0] * b_max)))
        ax.annotate(str(b + 1), xy=(x[i], y[i]), xytext=spot[1], textcoords="offset points",
                    fontsize=10, fontweight="bold", color=BRANCH_STYLE[b]["color"],
                    ha="center", va="center",
                    arrowprops=dict(arrowstyle="-", color=BRANCH_STYLE[b]["color"], lw=0.7))


def loop_width(field, branch, m):
    """Largest gap in M/Ms between the descent and the final rise."""
    down, up = branch == 1, branch == 2
    if down.sum() < 2 or up.sum() < 2:
        return 0.0
    order = np.argsort(field[up])
    return float(np.max(np.abs(m[down] - np.interp(field[down], field[up][order], m[up][order]))))


def mark_loop_features(ax, attrs):
    """Coercive field B_c and remanence M_r, when the loop has them (not for Fig. 1.6). The
    labels sit outside the loop: below right of +B_c, above left of M_r."""
    bc, mr = attrs.get("coercive_field_T", math.nan), attrs.get("remanence", math.nan)
    arrow = dict(arrowstyle="->", color="0.2", lw=0.8)
    if math.isfinite(bc) and bc > 0:
        ax.plot([-bc, bc], [0.0, 0.0], "o", color="k", markersize=4, zorder=5)
        ax.annotate(rf"$B_c$ = {bc:.3g} T", xy=(bc, 0.0), xytext=(22, -34),
                    textcoords="offset points", fontsize=9, arrowprops=arrow)
    if math.isfinite(mr) and mr > 0:
        ax.plot([0.0, 0.0], [mr, -mr], "s", color="k", markersize=4, zorder=5)
        ax.annotate(rf"$M_r$ = {mr:.3g} $M_s$", xy=(0.0, mr), xytext=(-110, -30),
                    textcoords="offset points", fontsize=9, ha="center", arrowprops=arrow)


def describe_material(ax, attrs):
    chi0 = attrs.get("initial_susceptibility", math.nan)
    ms = attrs.get("saturation_magnetization_A_per_m", math.nan)
    if math.isfinite(chi0) and math.isfinite(ms):
        mantissa, exponent = f"{ms:.3e}".split("e")
        ms_text = rf"{float(mantissa):g} \times 10^{{{int(exponent)}}}"
        ax.text(0.03, 0.87, rf"$\chi_0$ = {chi0:g}, $M_s$ = ${ms_text}$ A/m",
                transform=ax.transAxes, ha="left", va="top", fontsize=8, color="0.3")
