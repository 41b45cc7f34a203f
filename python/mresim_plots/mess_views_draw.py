"""Drawing pieces shared by the view figures: a cut's wireframe, its particle nodes, the
particles' outlines and magnetization arrows, axis labels (µm)."""

import math

import numpy as np
from matplotlib.collections import LineCollection
from matplotlib.patches import Circle

from .mess_lattice import in_plane, layer_in_plane
from .typography import UM_PAREN
from .view_options import AXES

PARTICLE_RED = "#d62728"  # the red particle-node markers of Figs. 4.3c and 4.12
WIRE_GREY = "0.45"
ARROW_COLOR = "#1f3fd6"


def axis_label(axis):
    return f"${AXES[axis]}$ {UM_PAREN}"


def layer_coordinates(grid, positions, plane):
    """(H, V, nodes): the in-plane coordinates (µm, 2D over the layer's grid, NaN where
    there is no node) of the layer's nodes at `positions`, and the node indices (-1 none)."""
    nodes = layer_in_plane(grid, plane.axis, plane.layer)
    h, v = in_plane(plane.axis)
    p = np.asarray(positions, dtype=float) * 1e6
    ok = nodes >= 0
    hh = np.full(nodes.shape, np.nan)
    vv = np.full(nodes.shape, np.nan)
    hh[ok] = p[nodes[ok], h]
    vv[ok] = p[nodes[ok], v]
    return hh, vv, nodes


def wireframe(ax, hh, vv, color=WIRE_GREY, linewidth=0.45, zorder=1, alpha=1.0):
    """The lattice lines of a cut: node to neighbouring node along both in-plane axes."""
    segments = []
    for a, b in ((hh, vv), (hh.T, vv.T)):
        start = np.stack([a[:-1], b[:-1]], axis=-1).reshape(-1, 2)
        end = np.stack([a[1:], b[1:]], axis=-1).reshape(-1, 2)
        ok = np.all(np.isfinite(start), axis=1) & np.all(np.isfinite(end), axis=1)
        segments.append(np.stack([start[ok], end[ok]], axis=1))
    lines = LineCollection(np.concatenate(segments), colors=color, linewidths=linewidth,
                           zorder=zorder, alpha=alpha)
    ax.add_collection(lines)
    return lines


def marker_size(count):
    """Scatter marker area (pt^2) for `count` nodes on a ~6 inch axes."""
    return max(2.0, min(30.0, 6000.0 / max(count, 1)))


def particle_layer_nodes(grid, nodes):
    """The layer's node indices (flat) that belong to a particle."""
    flat = nodes[nodes >= 0]
    return flat[grid.particle_id[flat] >= 0]


def particles_and_arrows(ax, views, step, plane, arrows=True, label=True, zorder=4):
    """The particles at `step` projected on the cut: a solid outline where the sphere meets
    the plane (its circle of intersection, radius sqrt(R^2 - d^2)), a dotted one of radius R
    where it does not (d: centre to plane, along the normal); centres as dots; the in-plane
    part of M as an arrow of length 2R M/Ms (a saturated particle's arrow spans a diameter,
    as particle_magnetization.png)."""
    d = views.data
    if d.centres is None or d.centres.ndim != 3 or step >= d.centres.shape[0]:
        return
    h, v = in_plane(plane.axis)
    c = d.centres[step] * 1e6
    r = views.radius * 1e6
    distance = np.abs(d.centres[step][:, plane.axis] - plane.coordinate) * 1e6
    labels = []  # label positions taken: particles behind one another get theirs below
    for p in range(c.shape[0]):
        if not np.all(np.isfinite(c[p])):
            continue
        if distance[p] < r:
            drawn = math.sqrt(r * r - distance[p] ** 2)
            ax.add_patch(Circle((c[p, h], c[p, v]), drawn, facecolor="none", edgecolor="k",
                                linewidth=1.0, zorder=zorder))
        else:
            drawn = r
            ax.add_patch(Circle((c[p, h], c[p, v]), r, facecolor="none", edgecolor="0.3",
                                linewidth=0.8, linestyle=":", zorder=zorder))
        if label:
            spot = np.array([c[p, h] + 0.72 * drawn, c[p, v] + 0.72 * drawn])
            while any(np.linalg.norm(spot - q) < 0.4 * r for q in labels):
                spot[1] -= 0.45 * r
            labels.append(spot)
            ax.annotate(str(p), tuple(spot), fontsize=7, color="0.2", zorder=zorder)
    ax.plot(c[:, h], c[:, v], "o", color="k", markersize=2.5, zorder=zorder + 1)
    if arrows and d.magnetization is not None and step < d.magnetization.shape[0]:
        m = d.magnetization[step] / d.ms
        length = m * 2.0 * r
        ax.quiver(c[:, h], c[:, v], length[:, h], length[:, v], angles="xy", scale_units="xy",
                  scale=1.0, color=ARROW_COLOR, units="dots", width=2.6, headwidth=3.5,
                  headlength=4.0, headaxislength=3.6, zorder=zorder + 2)


def equal_limits(ax, hh, vv, pad_fraction=0.03):
    """Limits around the finite coordinates, equal aspect."""
    hf, vf = hh[np.isfinite(hh)], vv[np.isfinite(vv)]
    if hf.size == 0:
        return
    pad = pad_fraction * max(np.ptp(hf), np.ptp(vf), 1e-9)
    ax.set_xlim(hf.min() - pad, hf.max() + pad)
    ax.set_ylim(vf.min() - pad, vf.max() + pad)
    ax.set_aspect("equal")
