"""The node lattice of a 3D run as a grid: node positions per step, node layers (the cuts of
the view figures) and cells, for mess_views*.py. No drawing here.

The lattice is the regular cubic one of Section 4.2.1: node n has the initial position
origin + l_e (i, j, k). The grid indices are recovered from /lattice/initial_positions, so that
the figures do not depend on the order in which mresim numbers the nodes.
"""

import glob
import math
import os
import re

import h5py
import numpy as np

from .common import PlotError


class LatticeGrid:
    """Initial positions (N x 3, m), particle_id (N, -1 polymer) and the grid they form."""

    def __init__(self, initial_positions, element_length, particle_id=None):
        x0 = np.asarray(initial_positions, dtype=float)
        if x0.ndim != 2 or x0.shape[1] != 3 or x0.shape[0] < 8:
            raise PlotError("/lattice/initial_positions is not an N x 3 array of 8 or more nodes")
        le = float(element_length) if element_length is not None else math.nan
        if not math.isfinite(le) or le <= 0:
            steps = np.diff(np.unique(np.round(x0[:, 0], 15)))
            le = float(np.min(steps)) if steps.size else 1.0
        self.le = le
        self.x0 = x0
        self.origin = x0.min(axis=0)
        scaled = (x0 - self.origin) / le
        self.index = np.rint(scaled).astype(int)
        if np.max(np.abs(scaled - self.index)) > 1e-3:
            raise PlotError("/lattice/initial_positions do not lie on a cubic grid of "
                            f"element_length {le:g} m")
        self.shape = tuple(int(v) for v in self.index.max(axis=0) + 1)
        self.node = np.full(self.shape, -1, dtype=np.int64)
        self.node[tuple(self.index.T)] = np.arange(x0.shape[0])
        if np.count_nonzero(self.node >= 0) != x0.shape[0]:
            raise PlotError("/lattice/initial_positions has two nodes at one grid point")
        self.particle_id = (np.asarray(particle_id, dtype=np.int64)
                            if particle_id is not None and np.size(particle_id) == x0.shape[0]
                            else np.full(x0.shape[0], -1, dtype=np.int64))
        self._cell_particle = None

    @property
    def lengths(self):
        return (np.array(self.shape) - 1) * self.le

    def coordinate(self, axis, layer):
        """Initial coordinate (m) of node layer `layer` normal to `axis`."""
        return self.origin[axis] + layer * self.le

    def nearest_layer(self, axis, coordinate):
        return int(np.clip(np.rint((coordinate - self.origin[axis]) / self.le), 0,
                           self.shape[axis] - 1))

    def layer_nodes(self, axis, layer):
        """Node indices of one layer as a 2D array over the two in-plane axes (in_plane(axis)
        order), -1 where the grid has no node."""
        return np.take(self.node, layer, axis=axis)

    def gridded(self, values, fill=math.nan):
        """Per-node values (N x ...) -> an array over the grid (nx, ny, nz, ...)."""
        values = np.asarray(values, dtype=float)
        out = np.full(self.shape + values.shape[1:], fill)
        out[tuple(self.index.T)] = values
        return out

    def cell_particle(self):
        """Per cell (nx-1, ny-1, nz-1): the particle whose nodes are all 8 corners, else -1.
        These cells are the particle's voxels (Section 4.2.1, Fig. 4.2)."""
        if self._cell_particle is None:
            pid = np.full(self.shape, -2, dtype=np.int64)  # -2: no node there
            pid[tuple(self.index.T)] = self.particle_id
            corners = [pid[a:a + self.shape[0] - 1, b:b + self.shape[1] - 1,
                           c:c + self.shape[2] - 1]
                       for a in (0, 1) for b in (0, 1) for c in (0, 1)]
            first = corners[0]
            same = np.all([c == first for c in corners], axis=0) & (first >= 0)
            self._cell_particle = np.where(same, first, -1)
        return self._cell_particle

    def displacement_gradient(self, positions, axis=None, cells=None):
        """du_i/dX_j (nx-1, ny-1, nz-1, 3, 3) per cell at its centre: the gradient of the
        trilinear interpolation of the node displacements (the hexahedral element of the
        volume term, eq. 4.64), i.e. along each axis the mean of the cell's four edge
        differences over l_e. Exact for an affine deformation. NaN where a corner is missing
        or not finite. With `axis` and `cells` = (first, end): only those cell layers along
        `axis` (a slab about a cut; full-size lattices have a million cells)."""
        u = self.gridded(np.asarray(positions, dtype=float) - self.x0)
        if axis is not None:
            keep = [slice(None)] * 3
            keep[axis] = slice(cells[0], cells[1] + 1)  # the slab's node layers
            u = u[tuple(keep)]
        grad = np.empty(tuple(s - 1 for s in u.shape[:3]) + (3, 3))
        for j in range(3):
            d = np.diff(u, axis=j)  # differences along X_j
            # mean over the 2 x 2 edges of the cell along the other two axes
            others = [a for a in range(3) if a != j]
            for a in others:
                sl_lo = [slice(None)] * 3
                sl_hi = [slice(None)] * 3
                sl_lo[a], sl_hi[a] = slice(0, -1), slice(1, None)
                d = 0.5 * (d[tuple(sl_lo)] + d[tuple(sl_hi)])
            grad[..., :, j] = d / self.le
        return grad

    def slab(self, axis, layer):
        """(first, end): the cell layers along `axis` on either side of node layer `layer`."""
        return max(0, layer - 1), min(self.shape[axis] - 1, layer + 1)


def in_plane(axis):
    """The (horizontal, vertical) axes of a cut normal to `axis`: x-z for y (as Fig. 4.12),
    y-z for x, x-y for z."""
    return {0: (1, 2), 1: (0, 2), 2: (0, 1)}[axis]


def layer_in_plane(grid, axis, layer):
    """layer_nodes over the (horizontal, vertical) axes of in_plane(axis), which are the
    remaining axes in increasing order."""
    return grid.layer_nodes(axis, layer)


def cut_cells(grid, axis, layer, values, weights=None, first=0):
    """Per-cell values (nx-1, ny-1, nz-1, ...; along `axis` only the cell layers from `first`
    on when they are a slab) -> per quad of the node layer (the cut, in_plane order): the mean
    over the cells on both sides of the layer (one side on the box faces). weights (per cell of
    the whole lattice, bool): which cells count; a quad with none is NaN."""
    n = grid.shape[axis] - 1
    sides = [k for k in (layer - 1, layer) if 0 <= k < n]
    values = np.asarray(values, dtype=float)
    total = 0.0
    count = 0.0
    for k in sides:
        v = np.take(values, k - first, axis=axis)
        w = (np.take(weights, k, axis=axis) if weights is not None
             else np.ones(v.shape[:2], dtype=bool)) & np.all(
                 np.isfinite(v.reshape(v.shape[:2] + (-1,))), axis=2)
        wv = w.reshape(w.shape + (1,) * (v.ndim - 2))
        total = total + np.where(wv, v, 0.0)
        count = count + wv
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(count > 0, total / np.where(count > 0, count, 1), np.nan)


class StepPositions:
    """Node positions per step: datasets /positions/step_NNNNNN in results.h5, or files
    DIR/positions/step_NNNNNN.h5 holding /positions (what mresim writes,
    docs/outputs-3d.md)."""

    def __init__(self, run):
        self.run = run
        self._where = {}  # step -> ("results", name) or ("file", path)
        with run.h5() as f:
            if "positions" in f and isinstance(f["positions"], h5py.Group):
                for name in f["positions"]:
                    n = _step_number(name)
                    if n is not None:
                        self._where[n] = ("results", f"positions/{name}")
        for path in glob.glob(run.path(os.path.join("positions", "*.h5"))):
            n = _step_number(os.path.basename(path))
            if n is not None and n not in self._where:
                self._where[n] = ("file", path)
        self.steps = sorted(self._where)
        self._cache = {}

    def __contains__(self, step):
        return step in self._where

    def load(self, step):
        if step not in self._cache:
            kind, where = self._where[step]
            if kind == "results":
                with self.run.h5() as f:
                    x = np.asarray(f[where][()], dtype=float)
            else:
                with h5py.File(where, "r") as g:
                    if "positions" not in g:
                        raise PlotError(f"{where} has no dataset /positions")
                    x = np.asarray(g["positions"][()], dtype=float)
            if len(self._cache) > 4:  # a few steps at a time: full-size lattices are large
                self._cache.pop(next(iter(self._cache)))
            self._cache[step] = x
        return self._cache[step]


def _step_number(name):
    match = re.fullmatch(r"step_(\d+)(\.h5)?", name)
    return int(match.group(1)) if match else None
