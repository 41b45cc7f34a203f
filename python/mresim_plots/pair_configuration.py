"""configuration.png: the two spheres in the xz-plane at B = 0 and at the largest field of
the initial rise (Fig. 2.7(d), 2.8(d))."""

import math
import textwrap

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.patches import Circle, Patch

from .typography import UM, UM_PAREN, suptitle

STYLES = [
    (dict(facecolor="0.85", edgecolor="0.45", linestyle="--"), "equilibrium"),
    (dict(facecolor="#4a7fc1", edgecolor="#1b3b6f", alpha=0.65), "displaced"),
]


def plot(run, cases):
    n = len(cases)
    ncols = min(n, 3)
    nrows = math.ceil(n / ncols)
    width = 6.4 if ncols == 1 else 4.8 * ncols
    # equal aspect: size the panels to the tallest drawing
    aspect = max(np.ptp(frame(c)[1]) / np.ptp(frame(c)[0]) for c in cases)
    height = nrows * ((width / ncols - 0.7) * aspect + 0.8) + 0.1
    fig, axes = plt.subplots(nrows, ncols, squeeze=False, layout="constrained",
                             figsize=(width, height))
    for ax, case in zip(axes.flat, cases):
        draw_case(ax, case)
        if n > 1:
            ax.set_title("\n".join(textwrap.wrap(case["label"], 50)), fontsize=9)
    for ax in axes.flat[n:]:
        ax.set_visible(False)
    suptitle(run, fig)
    run.save(fig, "configuration.png")


def states(case):
    """Indices of B = 0 and of the largest |B| on the initial rise."""
    rise = np.flatnonzero(case["branch"] == 0)
    rise = rise if rise.size else np.arange(case["field"].size)
    return (rise[np.argmin(np.abs(case["field"][rise]))],
            rise[np.argmax(np.abs(case["field"][rise]))])


def centres(separation_m, theta_deg):
    """Sphere centres (um, in x and z) for a pair symmetric about the origin."""
    t = math.radians(theta_deg)
    half = 0.5 * separation_m * 1e6 * np.array([math.cos(t), math.sin(t)])
    return -half, half


def frame(case):
    """(x limits, z limits, middle of the field arrow) in um: room for both states, the
    arrow above them and the legend below."""
    r = case["radius"] * 1e6
    reach = np.array([0.5 * case["s0"] * 1e6, 0.0])
    for i in states(case):
        reach = np.maximum(reach, np.abs(centres(case["s"][i], case["theta"][i])[1]))
    x_extent, top = reach[0] + r, reach[1] + r
    xlim = np.array([-1.15 * x_extent, 1.15 * x_extent])
    zlim = np.array([-top - 1.7 * r, top + 1.5 * r])
    return xlim, zlim, np.array([-0.8 * x_extent, top + 0.6 * r])


def draw_case(ax, case):
    r_um = case["radius"] * 1e6
    handles = []
    for i, (style, word) in zip(states(case), STYLES):
        a, b = centres(case["s"][i], case["theta"][i])
        for c in (a, b):
            ax.add_patch(Circle(c, r_um, linewidth=1.2, **style))
        ax.plot([a[0], b[0]], [a[1], b[1]], color=style["edgecolor"], linewidth=0.8,
                marker=".", markersize=3)
        label = (f"B = {case['field'][i]:.2f} T ({word}), "
                 f"$S$ = {case['s'][i] * 1e6:.2f} {UM}, "
                 f"$\\theta$ = {case['theta'][i]:.2f}$^\\circ$")
        handles.append(Patch(label=label, **style))
    xlim, zlim, arrow_middle = frame(case)
    draw_field_arrow(ax, case["angle"], arrow_middle, 1.4 * r_um)
    ax.set_xlim(*xlim)
    ax.set_ylim(*zlim)
    ax.set_aspect("equal")
    ax.set_xlabel(f"$x$ {UM_PAREN}")
    ax.set_ylabel(f"$z$ {UM_PAREN}")
    ax.grid(alpha=0.2)
    ax.legend(handles=handles, loc="lower center", fontsize=7, framealpha=0.9)


def draw_field_arrow(ax, angle_deg, middle, length):
    """A teal arrow along the applied field, at theta_H from the x-axis."""
    t = math.radians(angle_deg)
    half = 0.5 * length * np.array([math.cos(t), math.sin(t)])
    tail, head = middle - half, middle + half
    ax.annotate("", xy=head, xytext=tail,
                arrowprops=dict(arrowstyle="-|>", color="teal", linewidth=1.6))
    ax.annotate(rf"$\vec B$ ($\theta_H$ = {angle_deg:g}$^\circ$)",
                xy=head if angle_deg < 45 else middle, xytext=(6, 0),
                textcoords="offset points", va="center", color="teal", fontsize=8)
