"""Displacement, strain and stress maps on a cut (strain_map_stepNNNN_<plane>.png): one panel
per --field-map, drawn on the deformed cut. Displacements are per node (interpolated across
the quads); strains and stresses per quad of the cut, the mean of the two cells on either
side of the node layer (mess_lattice.cut_cells, mess_strain_field)."""

import math

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.collections import LineCollection

from .mess_lattice import cut_cells, in_plane
from .mess_strain_field import FIELD_MAPS, StepFields
from .mess_views_cuts import _title
from .mess_views_draw import axis_label, equal_limits, layer_coordinates

PARTICLE_GREY = "0.8"


def map_values(views, fields, plane, name):
    """(values, nodal): the map on the cut, 2D over the layer's nodes (nodal) or its quads;
    displacements in µm, strains dimensionless, stresses in Pa."""
    spec = FIELD_MAPS[name]
    grid = views.grid
    if spec.nodal:
        _, _, nodes = layer_coordinates(grid, fields.positions, plane)
        values = np.full(nodes.shape, np.nan)
        per_node = fields.nodal(name) * 1e6
        values[nodes >= 0] = per_node[nodes[nodes >= 0]]
        return values, True
    weights = grid.cell_particle() < 0 if spec.polymer_only else None
    return cut_cells(grid, plane.axis, plane.layer, fields.cells(name), weights,
                     fields.first), False


def particle_faces(views, plane, every_side=True):
    """Quads of the cut inside a particle: every cell on either side of the node layer is a
    particle voxel (every_side), or at least one is (the particle touches the cut there)."""
    inside = (views.grid.cell_particle() >= 0).astype(float)
    share = cut_cells(views.grid, plane.axis, plane.layer, inside)
    return share > 0.999 if every_side else share > 0.0


def particle_boundary(hh, vv, inside):
    """Segments (in the deformed cut) between quads inside and outside the particles."""
    segments = []
    di = inside[1:, :] != inside[:-1, :]  # quads (i, j) | (i+1, j): edge at node column i+1
    for i, j in zip(*np.nonzero(di)):
        segments.append([(hh[i + 1, j], vv[i + 1, j]), (hh[i + 1, j + 1], vv[i + 1, j + 1])])
    dj = inside[:, 1:] != inside[:, :-1]  # quads (i, j) | (i, j+1): edge at node row j+1
    for i, j in zip(*np.nonzero(dj)):
        segments.append([(hh[i, j + 1], vv[i, j + 1]), (hh[i + 1, j + 1], vv[i + 1, j + 1])])
    return segments


def _limits(values, signed):
    v = values[np.isfinite(values)]
    if v.size == 0:
        return (-1.0, 1.0) if signed else (0.0, 1.0)
    top = float(np.max(np.abs(v)))
    top = top if top > 0 else 1.0
    if signed:
        return -top, top
    low = float(v.min())
    return (0.0, top) if low >= 0 else (low, top)


def _layout(count, hh, vv):
    """(rows, cols, figsize): tall cuts side by side, others two to a row."""
    hf, vf = hh[np.isfinite(hh)], vv[np.isfinite(vv)]
    ratio = np.ptp(hf) / max(np.ptp(vf), 1e-12)  # width / height of the cut
    cols = count if ratio < 0.6 or count == 1 else min(2, count)
    rows = math.ceil(count / cols)
    panel_h = 6.0 if rows == 1 else 4.2
    panel_w = min(6.5, max(2.2, panel_h * ratio)) + 1.2  # + colorbar
    return rows, cols, (min(16.0, panel_w * cols), panel_h * rows + 1.3)


def strain_map(run, views, step, plane, name):
    positions = views.positions.load(step)
    fields = StepFields(views.grid, positions, views.lam, views.mu,
                        slab=(plane.axis, views.grid.slab(plane.axis, plane.layer)))
    hh, vv, nodes = layer_coordinates(views.grid, positions, plane)
    if not (np.all(np.isfinite(hh)) and np.all(np.isfinite(vv))):
        return  # a cut with holes or non-finite positions: no quads to colour
    # outlined wherever a particle touches the cut: also a particle whose voxels lie on one
    # side of the node layer only
    boundary = particle_boundary(hh, vv, particle_faces(views, plane, every_side=False))
    rows, cols, size = _layout(len(views.field_maps), hh, vv)
    fig, axes = plt.subplots(rows, cols, figsize=size, squeeze=False, layout="constrained")
    h, v = in_plane(plane.axis)
    for ax, map_name in zip(axes.flat, views.field_maps):
        spec = FIELD_MAPS[map_name]
        values, nodal = map_values(views, fields, plane, map_name)
        low, high = _limits(values, spec.signed)
        cmap = plt.get_cmap("RdBu_r" if spec.signed else "viridis").with_extremes(
            bad=PARTICLE_GREY)
        mesh = ax.pcolormesh(hh, vv, np.ma.masked_invalid(values), cmap=cmap, vmin=low,
                             vmax=high, shading="gouraud" if nodal else "flat", rasterized=True)
        if boundary:
            ax.add_collection(LineCollection(boundary, colors="k", linewidths=0.8, zorder=3))
        bar = fig.colorbar(mesh, ax=ax, shrink=0.85)
        bar.set_label(spec.label, fontsize=8)
        bar.ax.tick_params(labelsize=7)
        bar.formatter.set_powerlimits((-2, 3))
        bar.formatter.set_useMathText(True)
        bar.update_ticks()
        ax.set_title(f"{spec.title}\n{spec.symbol}", fontsize=9)
        equal_limits(ax, hh, vv, pad_fraction=0.01)
        ax.set_xlabel(axis_label(h), fontsize=8)
        ax.set_ylabel(axis_label(v), fontsize=8)
        ax.tick_params(labelsize=7)
    for ax in axes.flat[len(views.field_maps):]:
        ax.set_visible(False)
    notes = "black outlines: particle voxels at the cut"
    if any(FIELD_MAPS[m].polymer_only for m in views.field_maps):
        notes += (rf"; stress: Hooke's law, $\mu$ = {views.mu / 1e3:.3g} kPa, "
                  rf"$\lambda$ = {views.lam / 1e3:.3g} kPa ({views.profile} lattice),"
                  "\nin the polymer only (grey: particle voxels on both sides of the cut)")
    _title(run, fig, f"{plane.title()}; {views.step_label(step)}\n{notes}")
    run.save(fig, name)
