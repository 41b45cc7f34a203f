"""pair_ensemble: loops averaged over a distribution of S0, one per case (Fig. 3.5)."""

import matplotlib.pyplot as plt
import numpy as np

from .common import BRANCH_STYLE, FIELD_LABEL, MAG_LABEL, PlotError, case_colors, require
from .loops import branch_segments
from .typography import suptitle, typeset

WIDENING_LABEL = r"$\Delta(M/M_s)$"


def plot(run):
    summary = run.table("summary.csv")
    require(summary, ["case", "branch", "B_T", "M_over_Ms"], "summary.csv")
    cases = split_cases(summary)
    if not cases:
        raise PlotError(f"{run.path('summary.csv')} has no rows")
    colors = case_colors(len(cases))
    first_quadrant(run, cases, colors)
    widening = run.optional_table("widening.csv")
    if widening is not None:
        require(widening, ["case", "B_T", "dM_over_Ms"], "widening.csv")
        loop_widening(run, cases, colors, widening)
    if "dM_dB_per_T" in summary:
        susceptibility(run, cases, colors)


def split_cases(summary):
    cases = []
    for index in np.unique(summary["case"]).astype(int):
        rows = summary["case"] == index
        label = typeset(str(summary["label"][rows][0])) if "label" in summary \
            else f"case {index}"
        cases.append(dict(index=index, label=label, field=summary["B_T"][rows],
                          branch=summary["branch"][rows].astype(int),
                          m=summary["M_over_Ms"][rows],
                          chi=summary["dM_dB_per_T"][rows] if "dM_dB_per_T" in summary else None))
    return cases


def returning_legs(case):
    """(branch, B, M/Ms) of the descent and the final rise for B >= 0, sorted by B."""
    for b in (1, 2):
        keep = (case["branch"] == b) & (case["field"] >= 0.0)
        order = np.argsort(case["field"][keep])
        yield b, case["field"][keep][order], case["m"][keep][order]


def first_quadrant(run, cases, colors):
    fig, ax = plt.subplots(figsize=(6.4, 4.8), layout="constrained")
    zoom = zoom_window(cases)
    inset = ax.inset_axes([0.5, 0.1, 0.46, 0.42]) if zoom else None
    for case, color in zip(cases, colors):
        for b, x, y in returning_legs(case):
            style = dict(color=color, linestyle=BRANCH_STYLE[b]["linestyle"], linewidth=1.5)
            ax.plot(x, y, label=case["label"] if b == 1 else None, **style)
            if inset is not None:
                inset.plot(x, y, **style)
    ax.set_xlim(left=0.0)
    ax.set_ylim(bottom=0.0)
    if inset is not None:
        set_zoom(inset, cases, zoom)
        ax.indicate_inset_zoom(inset, edgecolor="0.4")
    ax.set_xlabel(FIELD_LABEL)
    ax.set_ylabel(MAG_LABEL)
    ax.grid(alpha=0.25)
    ax.add_artist(ax.legend(fontsize=8, loc="upper left"))
    handles = [plt.Line2D([], [], color="0.3", linestyle=BRANCH_STYLE[b]["linestyle"],
                          label=BRANCH_STYLE[b]["label"]) for b in (1, 2)]
    ax.legend(handles=handles, fontsize=8, loc="center left", bbox_to_anchor=(0.0, 0.62))
    suptitle(run, fig)
    run.save(fig, "ensemble_first_quadrant.png")


def zoom_window(cases, half_width=0.08):
    """A field window around the widest opening of the loops, or None without hysteresis."""
    best, centre = 0.0, None
    for case in cases:
        (_, x1, y1), (_, x2, y2) = returning_legs(case)
        if x1.size < 5 or x2.size < 5:
            continue
        diff = np.abs(y1 - np.interp(x1, x2, y2))
        if diff.max() > best:
            best, centre = diff.max(), x1[np.argmax(diff)]
    if best < 1e-3:
        return None
    span = half_width * max(np.max(np.abs(c["field"])) for c in cases)
    return max(centre - span, 0.0), centre + span


def set_zoom(inset, cases, zoom):
    ys = []
    for case in cases:
        for _, x, y in returning_legs(case):
            ys.append(y[(x >= zoom[0]) & (x <= zoom[1])])
    ys = np.concatenate(ys) if ys else np.array([0.0, 1.0])
    pad = 0.05 * (ys.max() - ys.min()) + 1e-6
    inset.set_xlim(*zoom)
    inset.set_ylim(ys.min() - pad, ys.max() + pad)
    inset.tick_params(labelsize=7)
    inset.grid(alpha=0.25)


def loop_widening(run, cases, colors, widening):
    fig, ax = plt.subplots(figsize=(6.4, 4.8), layout="constrained")
    smoothed = "dM_over_Ms_smoothed" in widening
    for case, color in zip(cases, colors):
        rows = widening["case"] == case["index"]
        x = widening["B_T"][rows]
        if smoothed:
            ax.plot(x, widening["dM_over_Ms"][rows], color=color, linewidth=0.7, alpha=0.35)
        y = widening["dM_over_Ms_smoothed" if smoothed else "dM_over_Ms"][rows]
        ax.plot(x, y, color=color, linewidth=1.6, label=case["label"])
    ax.axhline(0.0, color="0.8", linewidth=0.6, zorder=0)
    ax.set_xlabel(FIELD_LABEL)
    ax.set_ylabel(WIDENING_LABEL + " (descent $-$ final rise)")
    ax.grid(alpha=0.25)
    title = "five-point average (raw: faint)" if smoothed else None
    ax.legend(fontsize=8, title=title, title_fontsize=8)
    suptitle(run, fig)
    run.save(fig, "loop_widening.png")


def susceptibility(run, cases, colors):
    """One panel per branch, a colour per case."""
    branches = sorted(set(np.concatenate([c["branch"] for c in cases]).tolist()))
    fig, axes = plt.subplots(1, len(branches), sharey=True, squeeze=False,
                             figsize=(4.2 * len(branches), 4.4), layout="constrained")
    for ax, b in zip(axes.flat, branches):
        for case, color in zip(cases, colors):
            for seg_b, x, y in branch_segments(case["field"], case["branch"], case["chi"]):
                if seg_b == b:
                    ax.plot(x, y, color=color, linewidth=1.2, label=case["label"])
        ax.set_title(BRANCH_STYLE.get(b, {}).get("label", f"branch {b}"), fontsize=10)
        ax.set_xlabel(FIELD_LABEL)
        ax.grid(alpha=0.25)
    axes[0, 0].set_ylabel(r"$d(M/M_s)/dB$ (1/T)")
    axes[0, 0].legend(fontsize=8, loc="lower center")
    suptitle(run, fig)
    run.save(fig, "susceptibility.png")
