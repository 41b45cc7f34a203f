"""Synthetic run directories in the layouts mresim writes (small, fast, deterministic).

Each make_* function writes DIR/results.h5 plus the CSV files of one run type and returns
DIR. The numbers only need to look like the real thing, not be physics.
"""

import csv
import os

import h5py
import numpy as np

RADIUS = 1.5e-6


def sweep(b_max=1.0, step=0.05):
    """0 -> +max (branch 0), +max -> -max (1), -max -> +max (2), as mresim sweeps."""
    n = int(round(b_max / step))
    up = np.linspace(0.0, b_max, n + 1)
    down = np.linspace(b_max, -b_max, 2 * n + 1)[1:]
    rise = np.linspace(-b_max, b_max, 2 * n + 1)[1:]
    field = np.concatenate([up, down, rise])
    branch = np.concatenate([np.zeros(n + 1), np.ones(2 * n), np.full(2 * n, 2)]).astype(int)
    return field, branch


def pair_loop(s0, hc1, hc2, theta_h=0.0, step=0.05):
    """A pinched two-dipole loop: clustered (S = 2R) above hc2 until the field falls below hc1."""
    field, branch = sweep(step=step)
    clustered, state = np.zeros(field.size, bool), False
    for i, b in enumerate(np.abs(field)):
        state = b > hc2 or (state and b > hc1) if hc2 > 0 else False
        clustered[i] = state
    m = np.clip(np.where(clustered, 1.3, 1.1) * field, -1.0, 1.0)
    s = np.where(clustered, 2 * RADIUS, s0 - 0.2e-6 * np.minimum(field**2, 1.0))
    theta = np.where(clustered, 0.9 * theta_h, 0.2 * theta_h * field**2)
    return field, branch, m, s, theta


def _write_csv(path, header, rows):
    with open(path, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(header)
        w.writerows(rows)


def _root(f, run_type, title, extra_toml=""):
    f.attrs["run_type"] = run_type
    f.attrs["title"] = title
    f.attrs["input_toml"] = f'[run]\ntype = "{run_type}"\ntitle = "{title}"\n' + extra_toml


def make_pair_hysteresis(directory, cases):
    """cases: list of dicts with label, model ('single'/'three'), s0, hc1, hc2 (0: none),
    angle (deg)."""
    os.makedirs(directory, exist_ok=True)
    summary, critical = [], []
    with h5py.File(os.path.join(directory, "results.h5"), "w") as f:
        _root(f, "pair_hysteresis", "Synthetic pair loops",
              f"[material]\nradius = {RADIUS}\n")
        for i, c in enumerate(cases):
            field, branch, m, s, theta = pair_loop(c["s0"], c["hc1"], c["hc2"], c.get("angle", 0))
            g = f.create_group(f"cases/{i}")
            g.attrs.update(label=c["label"], spring_model=c["model"],
                           field_angle_deg=float(c.get("angle", 0.0)), rest_separation_m=c["s0"],
                           k12_N_per_m=0.04, k0_N_per_m=0.03 if c["model"] == "three" else 0.0)
            g["field"], g["branch"], g["magnetization_along_field"] = field, branch, m
            g["distance"], g["rotation"] = s, theta
            t = np.radians(theta)
            g["separation"] = np.stack([s * np.cos(t), 0 * s, s * np.sin(t)], axis=1)
            for j in range(field.size):
                summary.append([i, j, branch[j], field[j], s[j], s[j] - c["s0"], theta[j],
                                m[j], 0, 0, m[j], 0, 0, m[j], int(abs(m[j]) >= 1)]
                               + [0.0] * 7 + [3, 1])
            hyst = int(c["hc2"] > 0)
            critical.append([i, c["label"], hyst, c["hc1"] * hyst, c["hc2"] * hyst,
                             (c["hc2"] - c["hc1"]) * hyst, 5e-5 * hyst])
        f["cases"].attrs["count"] = len(cases)
    _write_csv(os.path.join(directory, "summary.csv"),
               ["case", "step", "branch", "B_T", "S_m", "S_minus_S0_m", "theta_deg", "m1_x",
                "m1_y", "m1_z", "m2_x", "m2_y", "m2_z", "M_over_Ms", "saturated", "E_total_J",
                "E_zeeman_J", "E_dipole_J", "E_self_J", "E_spring_J", "E_anchor_J",
                "E_penalty_J", "iterations", "converged"], summary)
    _write_csv(os.path.join(directory, "critical_fields.csv"),
               ["case", "label", "hysteresis", "HC1_T", "HC2_T", "dH_T", "uncertainty_T"],
               critical)
    return directory


def make_pair_map(directory, rows="k", threshold=True):
    os.makedirs(directory, exist_ok=True)
    s0 = np.linspace(3.2e-6, 13e-6, 25)
    if rows == "k":
        values = np.logspace(-3, np.log10(0.9), 12)
        s_max = 19.6e-6 * (values / 1e-3) ** -0.2  # eq. 2.10 falls as k^(-1/5)
    else:
        values = np.linspace(0.0, 90.0, 10)
        s_max = 10.4e-6 - 4.6e-6 * (values / 90.0) ** 2
    hyst = (s0[None, :] < s_max[:, None]) & (s0[None, :] > 4e-6)
    span = (s0[None, :] - 4e-6) / (s_max[:, None] - 4e-6)
    hc1 = np.where(hyst, 0.05 + 0.2 * span, 0.0)
    hc2 = np.where(hyst, hc1 + 0.6 * span**2 + 0.01, 0.0)
    dh = hc2 - hc1
    with h5py.File(os.path.join(directory, "results.h5"), "w") as f:
        _root(f, "pair_map", f"Synthetic {rows} map", f"[material]\nradius = {RADIUS}\n")
        g = f.create_group("map")
        g.attrs["row_parameter"] = rows
        g["row_values"], g["separations"] = values, s0
        g["HC1"], g["HC2"], g["dH"] = hc1, hc2, dh
        g["hysteresis"] = hyst.astype(np.int64)
    rows_out = [[r, c, values[r], s0[c], int(hyst[r, c]), hc1[r, c], hc2[r, c], dh[r, c],
                 values[r] if rows == "k" else 0.03, 0.0]
                for r in range(values.size) for c in range(s0.size)]
    _write_csv(os.path.join(directory, "summary.csv"),
               ["row", "col", "row_value", "S0_m", "hysteresis", "HC1_T", "HC2_T", "dH_T",
                "k12_N_per_m", "k0_N_per_m"], rows_out)
    if rows == "k" and threshold:
        _write_csv(os.path.join(directory, "threshold.csv"), ["k_N_per_m", "S0_threshold_m"],
                   zip(values, s_max))
    return directory


def make_pair_ensemble(directory, widening=True):
    os.makedirs(directory, exist_ok=True)
    labels = ["k = 9e-3 N/m", "k = 9e-2 N/m", "k = 9e-1 N/m"]
    summary, wide = [], []
    with h5py.File(os.path.join(directory, "results.h5"), "w") as f:
        _root(f, "pair_ensemble", "Synthetic ensemble")
        for i, label in enumerate(labels):
            field, branch = sweep(step=0.02)
            open_ = 0.03 / (i + 1) * np.exp(-((np.abs(field) - 0.4) / 0.15) ** 2)
            sign = np.where(branch == 1, 1.0, np.where(branch == 2, -1.0, 0.0))
            m = np.clip(1.2 * field + 0.5 * sign * open_ * np.sign(field), -1, 1)
            chi = np.abs(np.gradient(m)) / 0.02  # field step 0.02 T
            f.create_group(f"cases/{i}").attrs["label"] = label
            for j in range(field.size):
                summary.append([i, label, j, branch[j], field[j], m[j], chi[j]])
            pos = np.linspace(0.0, 1.0, 51)
            raw = 0.03 / (i + 1) * np.exp(-((pos - 0.4) / 0.15) ** 2)
            noisy = raw + 0.002 * np.sin(40 * pos)
            smooth = np.convolve(noisy, np.ones(5) / 5, mode="same")
            wide += [[i, label, b, d, s] for b, d, s in zip(pos, noisy, smooth)]
    _write_csv(os.path.join(directory, "summary.csv"),
               ["case", "label", "step", "branch", "B_T", "M_over_Ms", "dM_dB_per_T"], summary)
    if widening:
        _write_csv(os.path.join(directory, "widening.csv"),
                   ["case", "label", "B_T", "dM_over_Ms", "dM_over_Ms_smoothed"], wide)
    return directory


def make_curve(directory, run_type):
    """froehlich_kennelly (anhysteretic) or preisach (hard loop)."""
    os.makedirs(directory, exist_ok=True)
    field, branch = sweep(step=0.02)
    if run_type == "preisach":
        shift = np.where(branch == 1, -0.35, 0.35)
        m = np.tanh((field - shift) / 0.15)
        m[branch == 0] = np.tanh(field[branch == 0] / 0.3) * np.tanh(field[branch == 0] / 0.2)
        attrs = dict(coercive_field_T=0.35, remanence=float(np.tanh(0.35 / 0.15)),
                     saturation_magnetization_A_per_m=np.nan)
    else:
        h = field / (4e-7 * np.pi)
        m = 70 * h / (1.6e6 + 70 * np.abs(h))
        attrs = dict(coercive_field_T=0.0, remanence=0.0, initial_susceptibility=70.0,
                     saturation_magnetization_A_per_m=1.6e6)
    with h5py.File(os.path.join(directory, "results.h5"), "w") as f:
        _root(f, run_type, f"Synthetic {run_type}")
        g = f.create_group("curve")
        g["field"], g["branch"], g["magnetization"] = field, branch, m
        g.attrs.update(attrs)
    _write_csv(os.path.join(directory, "summary.csv"), ["step", "branch", "B_T", "M_over_Ms"],
               [[j, branch[j], field[j], m[j]] for j in range(field.size)])
    return directory


DH_RESOLVED_COLUMN = "dH_resolved"  # as python/mresim_plots/pair_map.py reads it


def add_dh_resolved(directory, threshold_t=0.02):
    """A dH_resolved column in a pair_map summary.csv: 0 where 0 < dH < threshold_t (below the
    critical-field tolerance), else 1. Returns the (row, col) pairs marked 0."""
    path = os.path.join(directory, "summary.csv")
    with open(path, newline="") as fh:
        rows = list(csv.DictReader(fh))
    unresolved = []
    for r in rows:
        dh, hyst = float(r["dH_T"]), int(float(r["hysteresis"]))
        below = hyst > 0 and dh < threshold_t
        r[DH_RESOLVED_COLUMN] = "0" if below else "1"
        if below:
            unresolved.append((int(r["row"]), int(r["col"])))
    _write_csv(path, list(rows[0].keys()), [list(r.values()) for r in rows])
    return unresolved
