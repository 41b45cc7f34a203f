"""The view figures of the 3D runs: what the lattice, the particles and the strain look like
(Figs. 4.2, 4.3, 4.7, 4.10, 4.12, 4.20, 4.22-4.24, 4.27). Drawn only when the run wrote node
positions ([output] node_positions = true); docs/outputs-3d.md#view-figures lists them.

Entry point plot_views(run, data), data a mess.MessData. The steps, planes, particle and maps
come from run.options (view_options.py; `mresim plot DIR --step ... --plane ...`):

  initial_configuration.png        Figs. 4.3, 4.7, 4.10, 4.20: a) outside of the box, b) the
                                   particle nodes, c) the cut (first plane) with the particle
                                   nodes in red, d) the particle nodes shaded by depth
  particle_nodes_orthographic.png  Fig. 4.24: the particle nodes seen along x, y and z, shaded
                                   by depth
  particle_voxels.png              Fig. 4.2: the cells of --particle (default 0) as cubes
  lattice_cut.png                  Fig. 4.12: the deformed cut at the last step, y through
                                   particle 0 (no --step, --plane or --particle given); else
                                   lattice_cut_stepNNNN_<plane>.png per step and plane
  magnetization_cut_stepNNNN.png   Figs. 4.22, 4.23, 4.27: the cut with the particles and their
                                   M (in-plane part); _<plane> added when --plane is given
  strain_map_stepNNNN_<plane>.png  displacement, strain and stress maps on the cut
                                   (--field-map; mess_strain_field.py)
  animation.mp4 / animation.gif    with --animate only: the cut and the particles over the
                                   steps (mess_animation.py)

<plane> is the axis and the cut's initial coordinate, e.g. y4.20um.
"""

import math

import numpy as np

from . import mess_animation, mess_strain_field, mess_views_cuts, mess_views_fields, \
    mess_views_initial
from .mess_lattice import LatticeGrid, StepPositions
from .typography import UM
from .view_options import AXES, DEFAULT_FIELD_MAPS, OptionError, any_set


class Plane:
    """A cut: the layer of nodes normal to `axis` whose initial coordinate is nearest to the
    one asked for."""

    def __init__(self, grid, axis, coordinate, description):
        self.axis = axis
        self.layer = grid.nearest_layer(axis, coordinate)
        self.coordinate = grid.coordinate(axis, self.layer)
        self.description = description
        self.tag = f"{AXES[axis]}{self.coordinate * 1e6:.2f}um"

    @property
    def name(self):
        return AXES[self.axis]

    def title(self):
        return f"cut at ${self.name}$ = {self.coordinate * 1e6:.3g} {UM} ({self.description})"


class Views:
    """Everything the view figures share: the grid, the positions, the resolved options."""

    def __init__(self, run, data, grid, positions):
        self.run, self.data, self.grid, self.positions = run, data, grid, positions
        options = run.options
        self.named = any_set(options)  # file names carry step and plane
        self.planes_given = bool(options.get("plane"))
        self.centres0 = _initial_centres(data)
        self.particle = self._particle(options.get("particle"))
        self.planes = self._planes(options.get("plane") or [])
        self.steps = self._steps(options.get("step") or [])
        self.steps_given = bool(options.get("step"))
        self.field_maps = list(options.get("field_map") or DEFAULT_FIELD_MAPS)
        self.animate = bool(options.get("animate"))
        profile = str(run.config.get("model", {}).get("profile", "physical"))
        self.lam, self.mu = mess_strain_field.run_lame(run, profile)
        self.profile = profile
        self.radius = data.radius if math.isfinite(data.radius) else _radius(run)

    # ------------------------------------------------------------ option resolution

    def _particle(self, particle):
        count = self.centres0.shape[0]
        if particle is None:
            return 0 if count else None
        if particle >= count:
            raise OptionError(f"--particle {particle}: the run has {count} particle(s), "
                              f"numbered 0 to {count - 1}" if count else
                              f"--particle {particle}: the run has no particles")
        return particle

    def _planes(self, specs):
        if not specs:
            if self.particle is None:
                specs = [dict(axis=1, kind="mid", value=None, text="y=mid")]
            else:
                specs = [dict(axis=1, kind="particle", value=None, text="y")]
        planes, seen = [], set()
        for spec in specs:
            plane = self._plane(spec)
            if (plane.axis, plane.layer) not in seen:
                seen.add((plane.axis, plane.layer))
                planes.append(plane)
        return planes

    def _plane(self, spec):
        axis, grid = spec["axis"], self.grid
        if spec["kind"] == "mid":
            return Plane(grid, axis, grid.origin[axis] + 0.5 * grid.lengths[axis],
                         "halfway through the box")
        if spec["kind"] == "particle":
            k = self.particle if spec["value"] is None else spec["value"]
            count = self.centres0.shape[0]
            if k is None or k >= count:
                raise OptionError(f"--plane '{spec['text']}': the run has {count} particle(s)"
                                  + (f", numbered 0 to {count - 1}" if count else
                                     "; give a coordinate, e.g. y=mid"))
            return Plane(grid, axis, self.centres0[k, axis], f"through particle {k}")
        low = grid.origin[axis] - 0.5 * grid.le
        high = grid.origin[axis] + grid.lengths[axis] + 0.5 * grid.le
        value = spec["value"]
        if not low <= value <= high:
            raise OptionError(
                f"--plane '{spec['text']}': {AXES[axis]} = {value:g} m is outside the lattice; "
                f"allowed: {grid.origin[axis]:g} to {grid.origin[axis] + grid.lengths[axis]:g} m"
                f" ({grid.origin[axis] * 1e6:g} to "
                f"{(grid.origin[axis] + grid.lengths[axis]) * 1e6:g} um)")
        return Plane(grid, axis, value, f"nearest layer to {AXES[axis]} = {value * 1e6:.3g} {UM}")

    def _steps(self, specs):
        count = self.data.b_along.size
        have = self.positions.steps
        if not specs:
            return [have[-1]] if have else []
        wanted = []
        for spec in specs:
            if spec[0] == "all":
                wanted += have
            elif spec[0] == "last":
                wanted.append(have[-1])
            else:
                first, last = spec[1], spec[-1]
                text = str(first) if spec[0] == "index" else f"{first}-{last}"
                if last >= count:
                    raise OptionError(f"--step {text}: the run has {count} step(s), numbered 0 "
                                      f"to {count - 1}")
                missing = [n for n in range(first, last + 1) if n not in self.positions]
                if missing:
                    raise OptionError(f"--step {text}: no node positions for step {missing[0]} "
                                      f"(steps with positions: {_ranges(have)})")
                wanted += list(range(first, last + 1))
        return sorted(set(wanted))

    # ------------------------------------------------------------ labels

    def step_label(self, step):
        """'step 4: B = 40 mT' (B along the field direction, signed; the direction's angles
        when it is not +z; the load of strain and stress runs)."""
        d = self.data
        b = d.b_along[step] * 1e3
        text = f"step {step}: $B$ = {b:.4g} mT".replace("-", "\u2212")
        direction = _field_direction(d)
        if direction is not None and not np.allclose(direction, (0.0, 0.0, 1.0), atol=1e-9):
            theta = math.degrees(math.acos(max(-1.0, min(1.0, direction[2]))))
            phi = math.degrees(math.atan2(direction[1], direction[0]))
            text += rf" ($\theta_H$ = {theta:.0f}°, $\varphi$ = {phi:.0f}°)"
        if d.load_run and step < d.load_value.size:
            value = d.load_value[step]
            if d.load_unit == "rad":
                text += rf", $\gamma$ = {value:.3g} rad"
            elif d.load_unit == "Pa":
                text += f", stress {value:.4g} Pa"
            else:
                text += f", strain {value:.3g}"
        return text

    def file_name(self, kind, step, plane):
        return f"{kind}_step{step:04d}_{plane.tag}.png"


def plot_views(run, data):
    """Draws every view figure of the run into run.figures_dir: the initial configuration
    whenever results.h5 has the initial lattice (every run since it is always written), the
    cuts, maps and animation only with node positions per step (view options for steps given
    for a run without them are an error)."""
    views = make_views(run, data)
    if views is None:
        return
    run.views = views  # for tests and callers that want the resolved steps and planes
    mess_views_initial.initial_configuration(run, views)
    mess_views_initial.particle_nodes_orthographic(run, views)
    mess_views_initial.particle_voxels(run, views)
    if not views.positions.steps:
        return
    for step in views.steps:
        for plane in views.planes:
            name = (views.file_name("lattice_cut", step, plane) if views.named
                    else "lattice_cut.png")
            mess_views_cuts.lattice_cut(run, views, step, plane, name)
            name = (views.file_name("magnetization_cut", step, plane) if views.planes_given
                    else f"magnetization_cut_step{step:04d}.png")
            mess_views_cuts.magnetization_cut(run, views, step, plane, name)
            mess_views_fields.strain_map(run, views, step, plane,
                                         views.file_name("strain_map", step, plane))
    if views.animate:
        frames = views.steps if views.steps_given else views.positions.steps
        mess_animation.animation(run, views, frames, views.planes[0])


def make_views(run, data):
    """Views of the run, or None when it has no initial lattice. Options that need node
    positions per step are an error for a run without them: they could not be honoured."""
    x0 = data.initial_positions
    positions = StepPositions(run) if x0 is not None else None
    if x0 is None or not positions.steps:
        given = [o for o, v in (("--step", run.options.get("step")),
                                ("--plane", run.options.get("plane")),
                                ("--particle", x0 is None
                                 and run.options.get("particle") is not None),
                                ("--field-map", run.options.get("field_map")),
                                ("--animate", run.options.get("animate"))) if v]
        if given:
            raise OptionError(f"{', '.join(given)}: '{run.dir}' has no node positions (run with "
                              "[output] node_positions = true)")
        if x0 is None or data.particle_id is None:
            return None
    grid = LatticeGrid(x0, data.element_length, data.particle_id)
    return Views(run, data, grid, positions)


def _initial_centres(data):
    if data.initial_centres is not None and np.size(data.initial_centres) >= 3:
        return np.reshape(data.initial_centres, (-1, 3))
    if data.centres is not None and data.centres.ndim == 3:
        return data.centres[0]
    return np.zeros((0, 3))


def _field_direction(data):
    """The first non-zero field's direction (what /steps/field_projection is along)."""
    for b in data.field:
        n = np.linalg.norm(b)
        if n > 0:
            return b / n
    return None


def _radius(run):
    return run.radius()


def _ranges(steps):
    """[0, 1, 2, 5] -> '0-2, 5'."""
    parts, start = [], None
    for i, n in enumerate(steps):
        if start is None:
            start = n
        if i + 1 == len(steps) or steps[i + 1] != n + 1:
            parts.append(str(start) if start == n else f"{start}-{n}")
            start = None
    return ", ".join(parts)
