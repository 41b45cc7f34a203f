"""pair_orientation.png (strain and stress runs): the closest pair against the measured strain,
one curve per field: its centre separation (/steps/separation, µm) and, when the run wrote it,
the angle between its separation vector and the field (/steps/pair_angle, degrees).
Skipped with fewer than two particles (separation NaN at every step)."""

import math

import numpy as np
from matplotlib import pyplot as plt

from .common import case_colors
from .loops import CONTACT_STYLE
from .mess import strain_label
from .typography import UM_PAREN, suptitle


def pair_curves(data):
    """(field index, strain, separation in µm, angle in degrees or None) per field, in load
    order; None when the run has no usable separation."""
    sep = data.separation
    if sep is None or not np.any(np.isfinite(sep)):
        return None
    angle = data.pair_angle
    if angle is not None and (angle.shape != sep.shape or not np.any(np.isfinite(angle))):
        angle = None
    curves = []
    for k, steps in data.field_groups():
        steps = steps[np.argsort(data.load_index[steps], kind="stable")]
        curves.append((int(k), data.strain[steps], sep[steps] * 1e6,
                       None if angle is None else np.degrees(angle[steps])))
    return curves


def pair_orientation(run, data):
    curves = pair_curves(data)
    if not curves:
        return
    with_angle = curves[0][3] is not None
    ncols = 2 if with_angle else 1
    fig, axes = plt.subplots(1, ncols, squeeze=False, sharex=True,
                             figsize=(5.2 * ncols + 0.6, 4.6), layout="constrained")
    axes = axes[0]
    colors = case_colors(len(curves))
    for (k, x, s, a), color in zip(curves, colors):
        axes[0].plot(x, s, "o-", color=color, markersize=3.5, linewidth=1.1,
                     label=data.field_label(k), zorder=2)
        if with_angle:
            axes[1].plot(x, a, "o-", color=color, markersize=3.5, linewidth=1.1, zorder=2)
    contact = 2.0 * data.radius * 1e6
    low = min(np.nanmin(s) for _, _, s, _ in curves)
    if math.isfinite(contact) and low < 1.3 * contact:
        axes[0].axhline(contact, label=r"contact, $S = 2R$", **CONTACT_STYLE)
    axes[0].set_ylabel(f"closest pair: centre separation {UM_PAREN}")
    axes[0].legend(fontsize=8, loc="best")
    if with_angle:
        axes[1].set_ylabel(r"closest pair: angle to the field (degrees)")
    for ax in axes:
        ax.set_xlabel(strain_label(run, data))
        ax.grid(alpha=0.25)
    suptitle(run, fig)
    run.save(fig, "pair_orientation.png")
