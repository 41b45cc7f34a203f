"""pair_map: critical fields over (k, S0) or (theta_H, S0) (Figs. 2.5, 2.9)."""

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.patches import Patch

from .common import TAUPE, PlotError
from .typography import UM_PAREN, suptitle

S0_LABEL = f"$S_0$ {UM_PAREN}"
# (dataset, panel title, colourbar name)
# The critical fields are stored as mu0 H (T), the field axis of the loops.
PANELS = [("HC1", r"$\mu_0 H_{C1}$", r"$\mu_0 H_{C1}$"),
          ("HC2", r"$\mu_0 H_{C2}$", r"$\mu_0 H_{C2}$"),
          ("dH", r"$\mu_0 \Delta H = \mu_0 (H_{C2} - H_{C1})$", r"$\mu_0 \Delta H$")]
# Optional per-point flag (summary.csv column, or /map dataset of the same name): 1 where dH
# is resolved, 0 where it lies below the critical-field refinement tolerance, so that its
# value is noise (the raggedness of Fig. 2.5). Such points are drawn hollow.
DH_RESOLVED_COLUMN = "dH_resolved"
UNRESOLVED_LABEL = r"hollow: $\mu_0 \Delta H$ below the critical-field tolerance"


def plot(run):
    grid = read_grid(run)
    critical_fields_map(run, grid)
    dh_vs_s0(run, grid)


def read_grid(run):
    with run.h5() as f:
        if "map" not in f:
            raise PlotError(f"{run.h5_path} has no /map group")
        g = f["map"]
        param = g.attrs.get("row_parameter", "k")
        param = param.decode() if isinstance(param, bytes) else str(param)
        grid = dict(param=param, rows=g["row_values"][()], s0=g["separations"][()] * 1e6,
                    hysteresis=g["hysteresis"][()].astype(int) > 0,
                    **{key: g[key][()] for key, _, _ in PANELS})
        grid["threshold_h5"] = g["eq_2_10_threshold"][()] if "eq_2_10_threshold" in g else None
        resolved_h5 = g[DH_RESOLVED_COLUMN][()] if DH_RESOLVED_COLUMN in g else None
    if grid["dH"].shape != (grid["rows"].size, grid["s0"].size):
        raise PlotError(f"/map/dH has shape {grid['dH'].shape}, expected rows x separations")
    grid["is_k"] = grid["param"] == "k"
    grid["row_label"] = r"$k$ (N/m)" if grid["is_k"] else r"field angle $\theta_H$ (deg)"
    grid["threshold"] = thresholds(run, grid)
    grid["resolved"] = resolved_flags(run, grid, resolved_h5)
    return grid


def resolved_flags(run, grid, from_h5=None):
    """rows x separations booleans (True: dH resolved) from the DH_RESOLVED_COLUMN of
    summary.csv (rows `row`, `col`) or the /map dataset; None when the run has neither."""
    shape = grid["dH"].shape
    if from_h5 is not None and np.shape(from_h5) == shape:
        return np.asarray(from_h5) > 0
    table = run.optional_table("summary.csv")
    if table is None or not {DH_RESOLVED_COLUMN, "row", "col"} <= set(table):
        return None
    resolved = np.ones(shape, dtype=bool)
    r, c = table["row"].astype(int), table["col"].astype(int)
    inside = (r >= 0) & (r < shape[0]) & (c >= 0) & (c < shape[1])
    resolved[r[inside], c[inside]] = table[DH_RESOLVED_COLUMN][inside] > 0
    return resolved


def unresolved(grid):
    """Cells with hysteresis whose dH is below the tolerance (all False without the flag)."""
    if grid.get("resolved") is None:
        return np.zeros(grid["dH"].shape, dtype=bool)
    return grid["hysteresis"] & ~grid["resolved"]


def thresholds(run, grid):
    """Eq. 2.10 S0 thresholds (um) per row for k maps: threshold.csv, else the h5 copy."""
    if not grid["is_k"]:
        return None
    table = run.optional_table("threshold.csv")
    if table is not None and {"k_N_per_m", "S0_threshold_m"} <= set(table):
        order = np.argsort(table["k_N_per_m"])
        return np.interp(np.log(grid["rows"]), np.log(table["k_N_per_m"][order]),
                         table["S0_threshold_m"][order]) * 1e6
    if grid["threshold_h5"] is not None:
        return grid["threshold_h5"] * 1e6
    return None


def edges(centres, log):
    """Cell edges around sorted cell centres (geometric midpoints on a log axis)."""
    c = np.log(centres) if log else np.asarray(centres, dtype=float)
    if c.size == 1:
        e = np.array([c[0] - 0.5, c[0] + 0.5]) if not log else np.array([c[0] - 0.1, c[0] + 0.1])
    else:
        mid = 0.5 * (c[1:] + c[:-1])
        e = np.concatenate(([c[0] - (mid[0] - c[0])], mid, [c[-1] + (c[-1] - mid[-1])]))
    return np.exp(e) if log else e


def critical_fields_map(run, grid):
    x_edges = edges(grid["s0"], log=False)
    y_edges = edges(grid["rows"], log=grid["is_k"])
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.6), layout="constrained", sharey=True)
    for ax, (key, name, short) in zip(axes, PANELS):
        values = np.ma.masked_where(~grid["hysteresis"], grid[key])
        cmap = plt.get_cmap("viridis").copy()
        cmap.set_bad(TAUPE)
        mesh = ax.pcolormesh(x_edges, y_edges, values, cmap=cmap, shading="flat")
        fig.colorbar(mesh, ax=ax, label=f"{short} (T)", pad=0.01)
        if grid["threshold"] is not None:
            ax.plot(grid["threshold"], grid["rows"], color="w", linestyle="--", linewidth=1.2,
                    label="eq. 2.10 threshold")
        if key == "dH" and np.any(unresolved(grid)):
            rows, cols = np.nonzero(unresolved(grid))
            ax.plot(grid["s0"][cols], grid["rows"][rows], "o", markersize=3.5, linestyle="none",
                    markerfacecolor="none", markeredgecolor="w", markeredgewidth=0.8)
        ax.set_xlim(x_edges[0], x_edges[-1])
        ax.set_ylim(y_edges[0], y_edges[-1])
        ax.set_xlabel(S0_LABEL)
        ax.set_title(name, fontsize=10)
    if grid["is_k"]:
        axes[0].set_yscale("log")
    axes[0].set_ylabel(grid["row_label"])
    handles = [Patch(facecolor=TAUPE, label="no hysteresis")]
    if grid["threshold"] is not None:
        handles.append(plt.Line2D([], [], color="w", linestyle="--", label="eq. 2.10 threshold"))
    legend = axes[0].legend(handles=handles, loc="upper right", fontsize=8, framealpha=0.85)
    legend.get_frame().set_facecolor("0.55" if grid["threshold"] is not None else "w")
    if np.any(unresolved(grid)):
        marker = plt.Line2D([], [], marker="o", markersize=3.5, linestyle="none",
                            markerfacecolor="none", markeredgecolor="w", markeredgewidth=0.8,
                            label=r"$\mu_0 \Delta H$ below the tolerance")
        dh_legend = axes[2].legend(handles=[marker], loc="upper right", fontsize=8,
                                   framealpha=0.85)
        dh_legend.get_frame().set_facecolor("0.55")
    suptitle(run, fig)
    run.save(fig, "critical_fields_map.png")


def selected_rows(n, count=5):
    """About `count` rows evenly spread over the index (log-spaced in k for log k rows)."""
    return sorted(set(np.round(np.linspace(0, n - 1, min(n, count))).astype(int).tolist()))


def dh_vs_s0(run, grid):
    rows = selected_rows(grid["rows"].size)
    fig, ax = plt.subplots(figsize=(6.8, 4.8), layout="constrained")
    colors = [plt.get_cmap("plasma")(x) for x in np.linspace(0.0, 0.8, len(rows))]
    shades = {}
    if grid["threshold"] is not None:
        shades = shade_threshold_ranges(ax, grid, rows, run.radius())
    handles = []
    hollow = unresolved(grid)
    for r, color in zip(rows, colors):
        dh = np.where(grid["hysteresis"][r], grid["dH"][r], 0.0)
        ax.plot(grid["s0"], dh, color=color, linewidth=1.4)
        (line,) = ax.plot(grid["s0"][~hollow[r]], dh[~hollow[r]], color=color, marker="o",
                          markersize=2.5, linestyle="none")
        if np.any(hollow[r]):
            ax.plot(grid["s0"][hollow[r]], dh[hollow[r]], color=color, marker="o",
                    markersize=4, linestyle="none", markerfacecolor="w", zorder=3)
        key = plt.Line2D([], [], color=color, marker="o", markersize=2.5, linewidth=1.4)
        handles.append((shades[r], key) if r in shades else key)
    ax.set_xlabel(S0_LABEL)
    ax.set_ylabel(r"$\mu_0 \Delta H = \mu_0 (H_{C2} - H_{C1})$ (T)")
    ax.set_xlim(grid["s0"][0], grid["s0"][-1])
    ax.set_ylim(bottom=0.0)
    ax.grid(alpha=0.25)
    labels = [row_name(grid, r) for r in rows]
    if np.any(hollow[rows]):
        handles.append(plt.Line2D([], [], color="0.3", marker="o", markersize=4, linestyle="none",
                                  markerfacecolor="w"))
        labels.append(UNRESOLVED_LABEL)
    ax.legend(handles, labels, fontsize=8, loc="upper left", title=legend_title(grid),
              title_fontsize=8)
    suptitle(run, fig)
    run.save(fig, "dH_vs_S0.png")


def row_name(grid, r):
    v = grid["rows"][r]
    return f"k = {v:.3g} N/m" if grid["is_k"] else rf"$\theta_H$ = {v:g}$^\circ$"


def legend_title(grid):
    if grid["threshold"] is None:
        return None
    return r"shaded: eq. 2.10 range $2R < S_0 < S_{0,\max}(k)$"


def shade_threshold_ranges(ax, grid, rows, radius_m):
    """Fig. 2.5(d): S0 from 2R to the eq. 2.10 threshold for each selected k, darkest grey for
    the largest k; the ranges nest, so the lightest (widest) goes underneath."""
    contact_um = 2.0 * radius_m * 1e6
    by_k = sorted(rows, key=lambda r: grid["rows"][r])
    greys = np.linspace(0.93, 0.7, len(by_k))
    return {r: ax.axvspan(contact_um, grid["threshold"][r], color=str(g), linewidth=0, zorder=0)
            for r, g in zip(by_k, greys)}
