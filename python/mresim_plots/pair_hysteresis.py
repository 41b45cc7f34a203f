"""pair_hysteresis: loops of two-dipole pairs (Figs. 2.2-2.4, 2.6-2.8, 3.4, 3.13)."""

import math
import textwrap

import matplotlib.pyplot as plt
import numpy as np

from . import pair_configuration
from .common import BRANCH_STYLE, FIELD_LABEL, MAG_LABEL, PlotError, case_colors, require
from .loops import CONTACT_STYLE, branch_style_legend, critical_field_lines, draw_loop
from .typography import UM_PAREN, suptitle, typeset

COLUMNS = ["case", "branch", "B_T", "S_minus_S0_m", "S_m", "theta_deg", "M_over_Ms"]
DISP_LABEL = f"$S - S_0$ {UM_PAREN}"
ROT_LABEL = r"rotation $\theta$ (deg)"
CONTACT_LABEL = r"contact, $S = 2R$"


def plot(run):
    summary = run.table("summary.csv")
    require(summary, COLUMNS, "summary.csv")
    cases = read_cases(run, summary)
    if not cases:
        raise PlotError(f"{run.path('summary.csv')} has no rows")
    magnetization(run, cases)
    displacement(run, cases)
    if any(np.any(np.abs(c["theta"]) > 1e-6) for c in cases):
        overlay(run, cases, "theta", ROT_LABEL, "rotation.png")
    three = [c for c in cases if c["model"] == "three"]
    if three:
        pair_configuration.plot(run, three)


def read_cases(run, summary):
    """One dict per case: the CSV columns of its rows plus the h5 case attributes."""
    critical = run.optional_table("critical_fields.csv")
    cases = []
    with run.h5() as f:
        for index in np.unique(summary["case"]).astype(int):
            rows = summary["case"] == index
            attrs = dict(f[f"cases/{index}"].attrs) if f"cases/{index}" in f else {}
            label = attrs.get("label") or (summary["label"][rows][0] if "label" in summary else "")
            case = dict(
                index=index, label=typeset(str(label)) or f"case {index}",
                model=str(attrs.get("spring_model", "")),
                angle=float(attrs.get("field_angle_deg", 0.0)),
                s0=float(attrs.get("rest_separation_m", summary["S_m"][rows][0])),
                field=summary["B_T"][rows], branch=summary["branch"][rows].astype(int),
                m=summary["M_over_Ms"][rows], s=summary["S_m"][rows],
                disp=summary["S_minus_S0_m"][rows] * 1e6, theta=summary["theta_deg"][rows],
                radius=run.radius(index), hc=None)
            if critical is not None:
                match = np.flatnonzero(critical["case"] == index)
                if match.size and critical["hysteresis"][match[0]] > 0:
                    case["hc"] = (critical["HC1_T"][match[0]], critical["HC2_T"][match[0]])
            cases.append(case)
    return cases


def overlay(run, cases, key, ylabel, name, critical_lines=True, extra=None):
    """One axes: Fig. 2.2 branch colours for one case, a colour per case for several."""
    fig, ax = plt.subplots(figsize=(6.4, 4.8), layout="constrained")
    if len(cases) == 1:
        c = cases[0]
        draw_loop(ax, c["field"], c["branch"], c[key])
        if critical_lines and c["hc"]:
            critical_field_lines(ax, *c["hc"])
        if extra:
            extra(ax, c)
        ax.legend(fontsize=8, loc="best")
    else:
        for c, color in zip(cases, case_colors(len(cases))):
            draw_loop(ax, c["field"], c["branch"], c[key], color=color)
            ax.plot([], [], color=color, label=c["label"])
            if critical_lines and c["hc"] and len(cases) <= 4:
                critical_field_lines(ax, *c["hc"], color=color, with_labels=False, alpha=0.5,
                                     shade=False)
        cases_legend = ax.legend(fontsize=8, loc="upper left")
        ax.add_artist(cases_legend)
        branch_style_legend(ax, np.concatenate([c["branch"] for c in cases]))
    ax.axhline(0.0, color="0.8", linewidth=0.6, zorder=0)
    ax.set_xlabel(FIELD_LABEL)
    ax.set_ylabel(ylabel)
    ax.grid(alpha=0.25)
    suptitle(run, fig)
    run.save(fig, name)


def magnetization(run, cases):
    overlay(run, cases, "m", MAG_LABEL + " (along the field)", "magnetization.png")


def displacement(run, cases):
    if len(cases) == 1:
        overlay(run, cases, "disp", DISP_LABEL, "displacement.png", extra=draw_contact)
        return
    n = len(cases)
    ncols = min(n, 3)  # 9 cases (Fig. 2.4): 3 x 3
    nrows = math.ceil(n / ncols)
    fig, axes = plt.subplots(nrows, ncols, sharex=True, squeeze=False,
                             figsize=(3.6 * ncols + 0.6, 2.7 * nrows + 0.8), layout="constrained")
    contact = False
    for ax, c in zip(axes.flat, cases):
        draw_loop(ax, c["field"], c["branch"], c["disp"], linewidth=1.3, label_branches=False)
        if c["hc"]:
            critical_field_lines(ax, *c["hc"], with_labels=False)
        contact = draw_contact(ax, c) or contact
        ax.set_title(wrap(c["label"]), fontsize=9)
        ax.grid(alpha=0.25)
    for ax in axes.flat[n:]:
        ax.set_visible(False)
    for ax in axes[:, 0]:
        ax.set_ylabel(DISP_LABEL)
    for i, ax in enumerate(axes.flat[:n]):
        if i + ncols >= n:  # nothing drawn below this one
            ax.set_xlabel(FIELD_LABEL)
            ax.xaxis.set_tick_params(labelbottom=True)
    handles, labels = [], []
    for b, style in sorted(_branch_styles(cases).items()):
        handles.append(plt.Line2D([], [], color=style["color"], linestyle=style["linestyle"]))
        labels.append(style["label"])
    if any(c["hc"] for c in cases):
        handles.append(plt.Line2D([], [], color="0.3", linestyle="--", linewidth=0.9))
        labels.append(r"$\pm\mu_0 H_{C1}$, $\pm\mu_0 H_{C2}$")
        handles.append(plt.Rectangle((0, 0), 1, 1, color="0.5", alpha=0.1, linewidth=0))
        labels.append("bistable range")
    if contact:
        handles.append(plt.Line2D([], [], **{k: v for k, v in CONTACT_STYLE.items()
                                             if k != "zorder"}))
        labels.append(CONTACT_LABEL)
    # matplotlib 3.6 (Debian 12) has no loc="outside ...": keep a strip free at the bottom
    per_row = len(labels) if ncols == 3 else math.ceil(len(labels) / 2)
    strip = 0.2 * (1 + math.ceil(len(labels) / per_row)) / fig.get_figheight()
    fig.get_layout_engine().set(rect=(0.0, strip, 1.0, 1.0 - strip))
    fig.legend(handles, labels, loc="lower center", ncol=per_row, fontsize=8, frameon=False)
    suptitle(run, fig)
    run.save(fig, "displacement.png")


def _branch_styles(cases):
    present = set(np.concatenate([c["branch"] for c in cases]).tolist())
    return {b: s for b, s in BRANCH_STYLE.items() if b in present}


def draw_contact(ax, case):
    """A light dashed line behind the loop at surface contact (S = 2R, S - S0 = 2R - S0) when
    the pair gets near it."""
    contact_um = (2.0 * case["radius"] - case["s0"]) * 1e6
    if contact_um < 0 and np.min(case["disp"]) < 0.8 * contact_um:
        ax.axhline(contact_um, label=CONTACT_LABEL, **CONTACT_STYLE)
        return True
    return False


def wrap(label, width=44):
    return "\n".join(textwrap.wrap(label, width)) or label
