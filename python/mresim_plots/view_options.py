"""The plot options of the 3D view figures (`mresim plot DIR --step ... --plane ...`): their
syntax, checked before any file is read. What a value means for a given run (is step 12 there,
does particle 3 exist) is checked by mess_views when it resolves them.

    --step S        step numbers (0-based, as /steps/index), ranges A-B (inclusive), `last`,
                    `all`; repeatable and comma-separated: --step 0,5-7 --step last
    --plane P       the cut: `x`, `y` or `z` through the centre of --particle (default 0),
                    `y@K` through particle K's centre, `y=4.5e-6` (metres), `y=4.5um` (µm),
                    `y=mid` (halfway through the box); the cut is the layer of nodes whose
                    initial coordinate is nearest. Repeatable and comma-separated.
    --particle K    the particle of bare-axis planes and of particle_voxels.png (default 0)
    --field-map C   what strain_map_*.png shows, one panel per name (FIELD_MAP_NAMES);
                    repeatable and comma-separated; default u,eps_eq,green_eq,sigma_vm
    --animate       also write animation.mp4 (ffmpeg on PATH) or animation.gif
"""

import re

from .common import PlotError

AXES = "xyz"
TENSOR_COMPONENTS = ("xx", "yy", "zz", "xy", "xz", "yz")
# Every --field-map name: displacement (nodal), linear (small) strain, Green strain and the
# Hooke stress of the linear strain (per cell, docs/outputs-3d.md#view-figures).
FIELD_MAP_NAMES = (
    ["u", "ux", "uy", "uz"]
    + [f"eps_{c}" for c in TENSOR_COMPONENTS] + ["eps_eq", "eps_vol"]
    + [f"green_{c}" for c in TENSOR_COMPONENTS] + ["green_eq"]
    + [f"sigma_{c}" for c in TENSOR_COMPONENTS] + ["sigma_vm", "pressure"]
)
DEFAULT_FIELD_MAPS = ["u", "eps_eq", "green_eq", "sigma_vm"]

_STEP_ITEM = re.compile(r"(\d+)(?:-(\d+))?")
_PLANE = re.compile(r"([xyz])(?:(@)(\d+)|(=)(.+))?")
_LENGTH = re.compile(r"([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*(um|\u00b5m|m)?")


class OptionError(PlotError):
    """A plot option whose value is wrong (exit status 2, as other command-line errors)."""


def _items(values):
    """Repeated options and comma lists, flattened; empty items are errors."""
    for value in values:
        for item in str(value).split(","):
            yield value, item.strip()


def parse_steps(values):
    """--step values -> list of ('index', n), ('range', a, b), ('last',), ('all',)."""
    out = []
    for value, item in _items(values):
        match = _STEP_ITEM.fullmatch(item)
        if item in ("last", "all"):
            out.append((item,))
        elif match and match.group(2) is None:
            out.append(("index", int(match.group(1))))
        elif match and int(match.group(2)) >= int(match.group(1)):
            out.append(("range", int(match.group(1)), int(match.group(2))))
        else:
            raise OptionError(f"--step '{value}': '{item}' is not a step; allowed: step numbers "
                              "from 0, ranges A-B with A <= B, 'last', 'all' (comma-separated)")
    return out


def parse_planes(values):
    """--plane values -> list of dicts {axis, kind: 'particle'|'coordinate'|'mid', value, text}.
    kind 'particle' with value None means the --particle one."""
    out = []
    for value, item in _items(values):
        match = _PLANE.fullmatch(item)
        allowed = ("allowed: x, y or z (through the --particle centre), AXIS@K (through "
                   "particle K), AXIS=COORD (metres, e.g. y=4.5e-6, or y=4.5um), AXIS=mid")
        if not match:
            raise OptionError(f"--plane '{value}': '{item}' is not a plane; {allowed}")
        axis = AXES.index(match.group(1))
        if match.group(2):
            out.append(dict(axis=axis, kind="particle", value=int(match.group(3)), text=item))
        elif match.group(4):
            coordinate = match.group(5).strip()
            if coordinate == "mid":
                out.append(dict(axis=axis, kind="mid", value=None, text=item))
                continue
            length = _LENGTH.fullmatch(coordinate)
            if not length:
                raise OptionError(f"--plane '{value}': '{coordinate}' is not a coordinate; "
                                  f"{allowed}")
            scale = 1e-6 if length.group(2) in ("um", "\u00b5m") else 1.0
            out.append(dict(axis=axis, kind="coordinate", value=float(length.group(1)) * scale,
                            text=item))
        else:
            out.append(dict(axis=axis, kind="particle", value=None, text=item))
    return out


def parse_field_maps(values):
    out = []
    for value, item in _items(values):
        name = _canonical_map(item)
        if name not in FIELD_MAP_NAMES:
            raise OptionError(f"--field-map '{value}': unknown map '{item}'; allowed: "
                              + ", ".join(FIELD_MAP_NAMES))
        if name not in out:
            out.append(name)
    return out


def _canonical_map(name):
    """eps_zx -> eps_xz: the tensors are symmetric, either order names the component."""
    match = re.fullmatch(r"(eps|green|sigma)_([xyz])([xyz])", name)
    if match:
        a, b = sorted(match.group(2) + match.group(3), key=AXES.index)
        return f"{match.group(1)}_{a}{b}"
    return name


def parse_particle(value):
    if value is None:
        return None
    text = str(value).strip()
    if not re.fullmatch(r"\d+", text):
        raise OptionError(f"--particle '{value}': must be a particle number from 0")
    return int(text)


def parse(steps=(), planes=(), particle=None, field_maps=(), animate=False):
    """Run.options from the raw option values (lists of strings as given)."""
    return dict(step=parse_steps(steps), plane=parse_planes(planes),
                particle=parse_particle(particle), field_map=parse_field_maps(field_maps),
                animate=bool(animate))


def any_set(options):
    """True when a view option was given (the default figure names apply otherwise)."""
    return bool(options.get("step") or options.get("plane")
                or options.get("particle") is not None)
