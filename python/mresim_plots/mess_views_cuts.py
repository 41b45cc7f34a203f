"""The deformed cut of the lattice (Fig. 4.12) and the cut with the particles' magnetization
(Figs. 4.22, 4.23, 4.27), at one step through one plane."""

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.lines import Line2D

from .mess_lattice import in_plane
from .mess_views_draw import (ARROW_COLOR, PARTICLE_RED, axis_label, equal_limits,
                              layer_coordinates, marker_size, particle_layer_nodes,
                              particles_and_arrows, wireframe)
from .typography import UM_PAREN, typeset


def cut_figsize(hh, vv, extra_width=1.3, height=6.4, max_width=11.0):
    """Figure size for an equal-aspect cut of the given extent plus a colorbar or legend."""
    hf, vf = hh[np.isfinite(hh)], vv[np.isfinite(vv)]
    ratio = np.ptp(hf) / max(np.ptp(vf), 1e-12) if hf.size else 1.0
    width = min(max_width, max(3.2, (height - 1.0) * ratio) + extra_width)
    if width >= max_width:  # wide cuts: keep the width, shrink the height
        height = max(3.5, (max_width - extra_width) / max(ratio, 1e-12) + 1.0)
    return width, height


def _title(run, fig, text):
    fig.suptitle((typeset(run.title) + "\n" if run.title else "") + text, fontsize=9)


def lattice_cut(run, views, step, plane, name):
    """Fig. 4.12: the nodes of the layer at `step`, deformed, joined along both in-plane
    axes, coloured by the length of their displacement; particle nodes outlined red."""
    x0, x = views.grid.x0, views.positions.load(step)
    hh, vv, nodes = layer_coordinates(views.grid, x, plane)
    flat = nodes[nodes >= 0]
    displacement = np.linalg.norm(x[flat] - x0[flat], axis=1) * 1e6
    h, v = in_plane(plane.axis)
    fig, ax = plt.subplots(figsize=cut_figsize(hh, vv), layout="constrained")
    wireframe(ax, hh, vv)
    size = marker_size(flat.size)
    points = ax.scatter(x[flat, h] * 1e6, x[flat, v] * 1e6, c=displacement, s=size,
                        cmap="viridis", zorder=2)
    fig.colorbar(points, ax=ax, label=f"displacement $|u|$ {UM_PAREN}", shrink=0.8)
    particle = particle_layer_nodes(views.grid, nodes)
    if particle.size:
        ax.scatter(x[particle, h] * 1e6, x[particle, v] * 1e6, s=size * 1.6,
                   facecolors="none", edgecolors=PARTICLE_RED, linewidths=0.7, zorder=3,
                   label="particle nodes")
        ax.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.07), frameon=False)
    equal_limits(ax, hh, vv)
    ax.set_xlabel(axis_label(h))
    ax.set_ylabel(axis_label(v))
    last = " (last)" if step == views.data.b_along.size - 1 else ""
    _title(run, fig, f"{plane.title()}\n{views.step_label(step)}{last}")
    run.save(fig, name)


def magnetization_cut(run, views, step, plane, name):
    """Figs. 4.22, 4.23, 4.27: the deformed cut (grey wireframe, particle nodes red) with the
    particles' outlines, centres and magnetization arrows (the in-plane part of 2R M/Ms)."""
    x = views.positions.load(step)
    hh, vv, nodes = layer_coordinates(views.grid, x, plane)
    h, v = in_plane(plane.axis)
    fig, ax = plt.subplots(figsize=cut_figsize(hh, vv, extra_width=0.6), layout="constrained")
    wireframe(ax, hh, vv, color="0.6", linewidth=0.4)
    particle = particle_layer_nodes(views.grid, nodes)
    size = marker_size(np.count_nonzero(nodes >= 0))
    if particle.size:
        ax.scatter(x[particle, h] * 1e6, x[particle, v] * 1e6, s=size, color=PARTICLE_RED,
                   alpha=0.55, linewidths=0, zorder=3)
    particles_and_arrows(ax, views, step, plane)
    equal_limits(ax, hh, vv)
    ax.set_xlabel(axis_label(h))
    ax.set_ylabel(axis_label(v))
    handles = [Line2D([], [], color=PARTICLE_RED, marker="o", linestyle="none", markersize=4,
                      alpha=0.55, label="particle nodes in the cut"),
               Line2D([], [], color="k", linewidth=1.0, label="particle in the cut"),
               Line2D([], [], color="0.3", linewidth=0.8, linestyle=":",
                      label="particle off the cut (projected)"),
               Line2D([], [], color=ARROW_COLOR, marker=r"$\rightarrow$", linestyle="none",
                      markersize=10, label=r"$2R\,M/M_s$, in-plane part")]
    # below the axes: inside, it would cover particles
    ax.legend(handles=handles, loc="upper center", bbox_to_anchor=(0.5, -0.07), ncol=2,
              fontsize=7, frameon=False)
    _title(run, fig, f"{plane.title()}\n{views.step_label(step)}")
    run.save(fig, name)

