"""animation.mp4 (ffmpeg on PATH) or animation.gif (Pillow): the deformed cut, the particles
and their magnetization over the steps of a run, e.g. the field loop of a hysteresis run.
Drawn only with --animate."""

import os
import shutil

import matplotlib.pyplot as plt
import numpy as np
from matplotlib import animation as mpl_animation

from .common import PlotError
from .mess_lattice import in_plane
from .mess_views_cuts import cut_figsize
from .mess_views_draw import (PARTICLE_RED, axis_label, layer_coordinates, particle_layer_nodes,
                              particles_and_arrows, wireframe)
from .typography import typeset

FPS = 3  # a step is a relaxation: a few per second can be followed by eye
DPI = 130


def writer():
    """(matplotlib writer, file name): FFMpegWriter to mp4 when ffmpeg is installed, else
    PillowWriter to gif."""
    if shutil.which("ffmpeg") and mpl_animation.FFMpegWriter.isAvailable():
        return mpl_animation.FFMpegWriter(fps=FPS, codec="libx264",
                                          extra_args=["-pix_fmt", "yuv420p"]), "animation.mp4"
    if mpl_animation.PillowWriter.isAvailable():
        return mpl_animation.PillowWriter(fps=FPS), "animation.gif"
    raise PlotError("--animate needs ffmpeg (mp4) or Pillow (gif); install with: apt-get "
                    "install ffmpeg, or python3-pil")


def animation(run, views, steps, plane):
    """One frame per step of `steps` (each with node positions): the cut's wireframe, its
    particle nodes, the particles and their M arrows; the limits fixed over all frames."""
    if not steps:
        return None
    h, v = in_plane(plane.axis)
    frames = []
    for step in steps:
        x = views.positions.load(step)
        frames.append(layer_coordinates(views.grid, x, plane) + (x,))
    low = [min(np.nanmin(f[0]) for f in frames), min(np.nanmin(f[1]) for f in frames)]
    high = [max(np.nanmax(f[0]) for f in frames), max(np.nanmax(f[1]) for f in frames)]
    pad = 0.03 * max(high[0] - low[0], high[1] - low[1])
    corners = np.array([[low[0], high[0]], [low[1], high[1]]])
    width, height = cut_figsize(corners[0], corners[1], extra_width=0.4, height=6.0)
    fig, ax = plt.subplots(figsize=(width, height), layout="constrained")
    movie, name = writer()
    os.makedirs(run.figures_dir, exist_ok=True)
    path = os.path.join(run.figures_dir, name)
    title = (typeset(run.title) + "\n" if run.title else "") + plane.title()
    with movie.saving(fig, path, dpi=DPI):
        for step, (hh, vv, nodes, x) in zip(steps, frames):
            ax.clear()
            wireframe(ax, hh, vv, color="0.55", linewidth=0.4)
            particle = particle_layer_nodes(views.grid, nodes)
            if particle.size:
                ax.scatter(x[particle, h] * 1e6, x[particle, v] * 1e6, s=6, color=PARTICLE_RED,
                           alpha=0.6, linewidths=0, zorder=3)
            particles_and_arrows(ax, views, step, plane)
            ax.set_xlim(low[0] - pad, high[0] + pad)
            ax.set_ylim(low[1] - pad, high[1] + pad)
            ax.set_aspect("equal")
            ax.set_xlabel(axis_label(h))
            ax.set_ylabel(axis_label(v))
            ax.set_title(f"{title}\n{views.step_label(step)}", fontsize=9)
            movie.grab_frame()
    plt.close(fig)
    run.written.append(path)
    return path
