"""The initial configuration: the box, the particle nodes, a cut (Figs. 4.3, 4.7, 4.10, 4.20),
orthographic depth-shaded views of the particle nodes (Fig. 4.24) and one particle's voxels
(Fig. 4.2)."""

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.colors import LinearSegmentedColormap

from .mess_lattice import in_plane
from .mess_views_cuts import _title
from .mess_views_draw import (PARTICLE_RED, axis_label, equal_limits, layer_coordinates,
                              marker_size, particle_layer_nodes, wireframe)
from .typography import UM, typeset

# Depth shading: dark = near the viewer, light = far (captions of Figs. 4.3d and 4.24).
DEPTH_CMAP = LinearSegmentedColormap.from_list("depth", ["#0b1f4a", "#3b6db3", "#c9d9ef"])
VIEW = dict(elev=22.0, azim=-58.0)  # the 3D panels' camera (matplotlib's degrees)
MAX_LINES = 40  # lattice lines per face direction in the outside view


def _box_aspect(ax, lengths):
    try:
        ax.set_box_aspect(lengths, zoom=0.95)
    except (AttributeError, TypeError, ValueError):  # zoom is new in matplotlib 3.6
        ax.set_box_aspect(lengths)


def _setup_3d(ax, grid):
    lengths = grid.lengths * 1e6
    low = grid.origin * 1e6
    ax.set_xlim(low[0], low[0] + lengths[0])
    ax.set_ylim(low[1], low[1] + lengths[1])
    ax.set_zlim(low[2], low[2] + lengths[2])
    _box_aspect(ax, lengths)
    ax.set_xlabel(axis_label(0), fontsize=8, labelpad=1)
    ax.set_ylabel(axis_label(1), fontsize=8, labelpad=1)
    ax.set_zlabel(axis_label(2), fontsize=8, labelpad=1)
    ax.tick_params(labelsize=6, pad=0)
    ax.view_init(**VIEW)


def _view_direction():
    """Unit vector from the scene towards matplotlib's 3D camera at VIEW."""
    elev, azim = np.radians(VIEW["elev"]), np.radians(VIEW["azim"])
    return np.array([np.cos(elev) * np.cos(azim), np.cos(elev) * np.sin(azim), np.sin(elev)])


def outside_view(ax, grid):
    """Fig. 4.3a: the three faces of the box lattice that face the camera, as surfaces with
    their lattice lines (every n-th line when there are more than MAX_LINES). Returns the
    largest n."""
    toward = _view_direction()
    x = grid.x0 * 1e6
    largest = 1
    for axis in range(3):
        side = grid.shape[axis] - 1 if toward[axis] > 0 else 0
        nodes = np.take(grid.node, side, axis=axis)
        coords = [np.where(nodes >= 0, x[nodes, a], np.nan) for a in range(3)]
        stride = [max(1, int(np.ceil((n - 1) / MAX_LINES))) for n in nodes.shape]
        largest = max(largest, *stride)
        ax.plot_surface(coords[0], coords[1], coords[2], rstride=stride[0], cstride=stride[1],
                        color="#d9c7a7", edgecolor="0.35", linewidth=0.3, shade=False,
                        alpha=1.0)
    return largest


def particle_scatter_3d(ax, grid, shade=False):
    """The particle nodes in 3D; shade: by depth along the view (dark = near)."""
    p = grid.particle_id >= 0
    x = grid.x0[p] * 1e6
    if shade:
        depth = x @ _view_direction()
        ax.scatter(x[:, 0], x[:, 1], x[:, 2], c=-depth, cmap=DEPTH_CMAP, s=6,
                   depthshade=False, linewidths=0)
    else:
        ax.scatter(x[:, 0], x[:, 1], x[:, 2], color=PARTICLE_RED, s=4, depthshade=False,
                   linewidths=0)


def viewer_side(axis):
    """+1 or -1: the side of the box along `axis` that the viewer of an orthographic view with
    the in_plane(axis) axes to the right and up is on (out of the page = right x up)."""
    h, v = in_plane(axis)
    return int(np.cross(np.eye(3)[h], np.eye(3)[v])[axis])


def view_name(axis):
    """'viewed from -y' (the x-z view), 'viewed from +x' (y-z), 'viewed from +z' (x-y)."""
    sign = "+" if viewer_side(axis) > 0 else "\u2212"
    return f"viewed from {sign}${'xyz'[axis]}$"


def depth_projection(fig, ax, grid, axis, colorbar=True):
    """The particle nodes in an orthographic view along `axis` (view_name), shaded by depth:
    dark = near the viewer, light = far. Near nodes are drawn last, over the far ones."""
    p = np.flatnonzero(grid.particle_id >= 0)
    h, v = in_plane(axis)
    side = viewer_side(axis)
    x = grid.x0[p] * 1e6
    x = x[np.argsort(side * x[:, axis])]  # far first
    cmap = DEPTH_CMAP if side < 0 else DEPTH_CMAP.reversed()
    points = ax.scatter(x[:, h], x[:, v], c=x[:, axis], cmap=cmap, s=marker_size(p.size) * 0.8,
                        linewidths=0)
    lengths = grid.lengths * 1e6
    low = grid.origin * 1e6
    ax.plot([low[h], low[h] + lengths[h], low[h] + lengths[h], low[h], low[h]],
            [low[v], low[v], low[v] + lengths[v], low[v] + lengths[v], low[v]],
            color="0.5", linewidth=0.8, linestyle="--")
    ax.set_xlim(low[h] - 0.02 * lengths[h], low[h] + 1.02 * lengths[h])
    ax.set_ylim(low[v] - 0.02 * lengths[v], low[v] + 1.02 * lengths[v])
    ax.set_aspect("equal")
    ax.set_xlabel(axis_label(h), fontsize=8)
    ax.set_ylabel(axis_label(v), fontsize=8)
    ax.tick_params(labelsize=7)
    if colorbar:
        bar = fig.colorbar(points, ax=ax, shrink=0.6)
        bar.set_label(f"depth: ${'xyz'[axis]}$ ({UM}); dark = near", fontsize=8)
        bar.ax.tick_params(labelsize=7)
    return points


def initial_cut(ax, views, plane):
    """Fig. 4.3c: the wireframe of the cut in the initial configuration, particle nodes red."""
    grid = views.grid
    hh, vv, nodes = layer_coordinates(grid, grid.x0, plane)
    wireframe(ax, hh, vv, linewidth=0.35)
    particle = particle_layer_nodes(grid, nodes)
    h, v = in_plane(plane.axis)
    if particle.size:
        ax.scatter(grid.x0[particle, h] * 1e6, grid.x0[particle, v] * 1e6, color=PARTICLE_RED,
                   s=marker_size(np.count_nonzero(nodes >= 0)) * 1.3, linewidths=0, zorder=3)
    equal_limits(ax, hh, vv)
    ax.set_xlabel(axis_label(h), fontsize=8)
    ax.set_ylabel(axis_label(v), fontsize=8)
    ax.tick_params(labelsize=7)


def _panel_letter(ax, letter):
    """'a)' above the axes' top left corner, clear of its title."""
    place = ax.text2D if hasattr(ax, "text2D") else ax.text
    place(-0.02, 1.04, f"{letter})", transform=ax.transAxes, fontsize=11, fontweight="bold",
          ha="right", va="bottom")


def initial_configuration(run, views):
    """Figs. 4.3, 4.7, 4.10, 4.20, panels a-d as their captions; in a row for a tall box (the
    dissertation's), two by two otherwise."""
    grid = views.grid
    plane = views.planes[0]
    lengths = grid.lengths
    tall = lengths[2] >= 1.3 * max(lengths[0], lengths[1])
    fig = plt.figure(figsize=(15.0, 7.2) if tall else (11.0, 10.0), layout="constrained")
    shape = (1, 4) if tall else (2, 2)
    a = fig.add_subplot(*shape, 1, projection="3d")
    b = fig.add_subplot(*shape, 2, projection="3d")
    c = fig.add_subplot(*shape, 3)
    d = fig.add_subplot(*shape, 4)
    left, right = (a, b), (c, d)
    stride = outside_view(left[0], grid)
    _setup_3d(left[0], grid)
    _panel_letter(left[0], "a")
    left[0].set_title("outside view of the box" + (f"\n(one lattice line in {stride} drawn)"
                                                   if stride > 1 else ""), fontsize=8)
    particle_scatter_3d(left[1], grid)
    _setup_3d(left[1], grid)
    _panel_letter(left[1], "b")
    left[1].set_title("particle nodes", fontsize=8)
    initial_cut(right[0], views, plane)
    _panel_letter(right[0], "c")
    right[0].set_title(f"cut at ${plane.name}$ = {plane.coordinate * 1e6:.3g} {UM}\n"
                       f"({plane.description}); red: particle nodes", fontsize=8)
    depth = 1 if plane.axis == 1 else plane.axis  # seen along the cut's normal
    depth_projection(fig, right[1], grid, depth)
    _panel_letter(right[1], "d")
    right[1].set_title(f"particle nodes {view_name(depth)}, shaded by depth", fontsize=8)
    n_p = views.centres0.shape[0]
    text = (f"initial configuration: {grid.shape[0]} x {grid.shape[1]} x {grid.shape[2]} nodes, "
            f"$l_e$ = {grid.le * 1e6:.4g} {UM}, {n_p} particle(s) of radius "
            f"{views.radius * 1e6:.3g} {UM}")
    volume_fraction = run.attrs.get("volume_fraction")
    if volume_fraction is None:
        with run.h5() as f:
            volume_fraction = f["lattice"].attrs.get("volume_fraction") if "lattice" in f \
                else None
    if volume_fraction is not None:
        text += rf", $\Phi$ = {float(volume_fraction) * 100:.3g} %"
    fig.suptitle((typeset(run.title) + "\n" if run.title else "") + text, fontsize=10)
    run.save(fig, "initial_configuration.png")


def particle_nodes_orthographic(run, views):
    """Fig. 4.24: the particle nodes seen along x, y and z, orthographic, shaded by depth."""
    grid = views.grid
    if not np.any(grid.particle_id >= 0):
        return
    lengths = grid.lengths
    # widths of the three views (y-z, x-z, x-y) relative to their heights
    ratios = [lengths[1] / lengths[2], lengths[0] / lengths[2], lengths[0] / lengths[1]]
    fig, axes = plt.subplots(1, 3, figsize=(12.0, 5.6), layout="constrained",
                             gridspec_kw=dict(width_ratios=[max(r, 0.35) for r in ratios]))
    for ax, axis, letter in zip(axes, (0, 1, 2), "abc"):
        depth_projection(fig, ax, grid, axis)
        _panel_letter(ax, letter)
        ax.set_title(view_name(axis), fontsize=9)
    _title(run, fig, "particle nodes, orthographic views; the shade is the depth into the page "
           "(dark = near the viewer)")
    run.save(fig, "particle_nodes_orthographic.png")


def particle_voxels(run, views):
    """Fig. 4.2: the voxels (cells with all eight nodes in the particle) of --particle."""
    k = views.particle
    if k is None:
        return
    grid = views.grid
    cells = grid.cell_particle() == k
    if not np.any(cells):
        return
    where = np.argwhere(cells)
    lo, hi = where.min(axis=0), where.max(axis=0) + 1
    filled = cells[lo[0]:hi[0], lo[1]:hi[1], lo[2]:hi[2]]
    # corner coordinates (µm) of the bounding block, relative to the particle centre
    centre = views.centres0[k] * 1e6
    axes_coords = [(grid.origin[a] + np.arange(lo[a], hi[a] + 1) * grid.le) * 1e6 - centre[a]
                   for a in range(3)]
    x, y, z = np.meshgrid(*axes_coords, indexing="ij")
    fig = plt.figure(figsize=(6.6, 6.2), layout="constrained")
    ax = fig.add_subplot(projection="3d")
    ax.voxels(x, y, z, filled, facecolors="#b0b0b0", edgecolors="0.25", linewidth=0.3)
    span = max(hi - lo) * grid.le * 1e6 / 2
    for setter in (ax.set_xlim, ax.set_ylim, ax.set_zlim):
        setter(-span, span)
    _box_aspect(ax, (1, 1, 1))
    ax.set_xlabel(f"$x - x_c$ ({UM})", fontsize=8)
    ax.set_ylabel(f"$y - y_c$ ({UM})", fontsize=8)
    ax.set_zlabel(f"$z - z_c$ ({UM})", fontsize=8)
    ax.tick_params(labelsize=7)
    ax.view_init(**VIEW)
    across = int(hi[0] - lo[0])
    text = (f"particle {k}: {int(cells.sum())} voxels, {across} across "
            f"($n_d$ = {(across - 1) / 2:g}), $l_e$ = {grid.le * 1e6:.4g} {UM}, "
            f"$R$ = {views.radius * 1e6:.3g} {UM}")
    _title(run, fig, text)
    run.save(fig, "particle_voxels.png")
