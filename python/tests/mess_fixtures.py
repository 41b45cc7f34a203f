"""Synthetic run directories of the 3D run types (mess_hysteresis, mess_magnetostriction,
mess_strain, mess_stress) in the results.h5 layout of docs/outputs-3d.md. Small and
deterministic; the numbers only need to look like the real thing, not be physics."""

import os

import h5py
import numpy as np

from fixtures import sweep

RADIUS = 1.5e-6
ELEMENT = 1.0e-6
NODES = (9, 7, 13)  # per axis: an 8 x 6 x 12 um box
MS = 1.6e6
ENERGY_TERMS = ["springs", "volume", "zeeman", "dipole", "self", "self_linearized", "wca",
                "load"]
# (title, equation) attributes as the C++ code writes them (src/mresim/mess/terms/*.cpp).
ENERGY_LABELS = {
    "springs": ("springs", "eq. 4.62"), "volume": ("volume elements", "eq. 4.64"),
    "zeeman": ("Zeeman", "eq. 4.70"), "dipole": ("dipole-dipole", "eq. 4.71"),
    "self": ("magnetic self", "eq. 4.76"), "self_linearized": ("magnetic self, linearized", "eq. 4.73"),
    "wca": ("WCA", "eq. 4.79"), "load": ("applied load", "-sum f.(x - x0)"),
}


def lattice():
    """Initial node positions (N x 3, node index iz + nz (ix + nx iy) as mresim numbers them),
    two particle centres along z, and particle_id per node (-1: polymer)."""
    nx, ny, nz = NODES
    positions = np.zeros((nx * ny * nz, 3))
    for iy in range(ny):
        for ix in range(nx):
            for iz in range(nz):
                positions[iz + nz * (ix + nx * iy)] = (ix * ELEMENT, iy * ELEMENT, iz * ELEMENT)
    centres = np.array([[4.5, 3.5, 3.5], [4.5, 3.5, 8.5]]) * ELEMENT
    particle_id = np.full(positions.shape[0], -1, dtype=np.int64)
    for p, c in enumerate(centres):
        particle_id[np.linalg.norm(positions - c, axis=1) <= RADIUS] = p
    return positions, centres, particle_id


def pair_centres(separation):
    """S x 2 x 3 centres: the pair along z about the box middle at the given separations."""
    mid = np.array([4.5, 3.5, 6.0]) * ELEMENT
    offset = np.zeros((separation.size, 2, 3))
    offset[:, 0, 2], offset[:, 1, 2] = -0.5 * separation, 0.5 * separation
    return mid + offset


def deformed(positions, step, shear=0.0):
    """Node positions after a simple shear of the top face along x plus a bump about the box
    middle that grows with the step number (up to 0.3 um)."""
    x = positions.copy()
    height = positions[:, 2].max()
    x[:, 0] += shear * positions[:, 2] / height * 1e-6
    middle = positions.mean(axis=0)
    bump = np.exp(-np.sum((positions - middle) ** 2, axis=1) / (3e-6) ** 2)
    x[:, 2] -= 0.3e-6 * min(1.0, (1 + step) / 10) * bump * np.sign(positions[:, 2] - middle[2])
    return x


def write_run(directory, run_type, field, field_index, load_index, load_value, load_unit,
              energy_density, centres, magnetization, measured_strain=None, analysis=None,
              positions=None):
    """results.h5 for one run. positions: None, "results" (/positions/step_NNNNNN datasets
    in results.h5) or "files" (DIR/positions/step_NNNNNN.h5 holding /positions)."""
    os.makedirs(directory, exist_ok=True)
    steps = field.shape[0]
    initial, initial_centres, particle_id = lattice()
    box = (np.array(NODES) - 1) * ELEMENT
    direction = next((b / np.linalg.norm(b) for b in field if np.linalg.norm(b) > 0),
                     np.array([0.0, 0.0, 1.0]))
    projection = field @ direction
    m_along = np.mean(magnetization @ direction, axis=1) / MS
    separation = np.linalg.norm(centres[:, 1] - centres[:, 0], axis=1)
    volume = np.prod(box)
    with h5py.File(os.path.join(directory, "results.h5"), "w") as f:
        title = f"Synthetic {run_type}"
        f.attrs["run_type"] = run_type
        f.attrs["title"] = title
        f.attrs["input_toml"] = (f'[run]\ntype = "{run_type}"\ntitle = "{title}"\n'
                                 f"[particles]\nradius = {RADIUS}\n"
                                 f"saturation_magnetization = {MS}\n")
        lat = f.create_group("lattice")
        lat.attrs["element_length"] = ELEMENT
        lat.attrs["particle_radius"] = RADIUS
        lat["shape"] = np.array(NODES, dtype=np.int64)
        lat["box_lengths"] = box
        lat["initial_centres"] = initial_centres
        s = f.create_group("steps")
        s["index"] = np.arange(steps, dtype=np.int64)
        s["field"] = field
        s["field_direction"] = direction
        s["field_projection"] = projection
        s["field_index"] = np.asarray(field_index, dtype=np.int64)
        s["load_index"] = np.asarray(load_index, dtype=np.int64)
        s["load_value"] = np.asarray(load_value, dtype=float)
        s["load_value"].attrs["unit"] = load_unit
        if measured_strain is not None:
            s["measured_strain"] = measured_strain
        total = energy_density * volume
        shares = [0.3, 0.25, -0.6, -0.2, 0.15, 0.12, 0.02, 0.0]
        for i, (name, share) in enumerate(zip(ENERGY_TERMS, shares)):
            s[f"energies/{name}"] = share * total + 1e-18 * np.sin(np.arange(steps) + i)
            s[f"energies/{name}"].attrs["title"], s[f"energies/{name}"].attrs["equation"] = \
                ENERGY_LABELS[name]
        s["energies"].attrs["terms"] = ",".join(ENERGY_TERMS)
        s["energies/total"] = total
        s["system_volume"] = np.full(steps, volume)
        s["energy_density"] = energy_density
        s["centres"] = centres
        s["magnetization"] = magnetization
        s["magnetization_projection"] = m_along
        s["separation"] = separation
        s["cluster_count"] = np.where(separation <= 2 ** (1 / 6) * 2 * RADIUS, 1, 2)
        s["solver/converged"] = np.ones(steps, dtype=np.int64)
        s["solver/iterations"] = np.full(steps, 40, dtype=np.int64)
        s["solver/max_force"] = np.full(steps, 1e-15)
        if analysis is not None:
            a = f.create_group("analysis")
            a.attrs["modulus_name"] = analysis.pop("modulus_name")
            for key, value in analysis.items():
                a[key] = value
        if positions is not None:  # "initial": the initial lattice only, as every run writes
            lat["initial_positions"] = initial
            lat["particle_id"] = particle_id
            for n in range(steps if positions != "initial" else 0):
                shear = float(load_value[n]) if load_unit == "rad" else 0.0
                x = deformed(initial, n, shear)
                if positions == "results":
                    f[f"positions/step_{n:06d}"] = x
                else:
                    os.makedirs(os.path.join(directory, "positions"), exist_ok=True)
                    name = os.path.join(directory, "positions", f"step_{n:06d}.h5")
                    with h5py.File(name, "w") as g:
                        g["positions"] = x
    return directory


def along_z(b):
    field = np.zeros((b.size, 3))
    field[:, 2] = b
    return field


def magnetizations(m_along):
    """S x 2 x 3: both particles along z at m_along Ms, slightly tilted in x."""
    m = np.zeros((m_along.size, 2, 3))
    m[:, :, 2] = (m_along * MS)[:, None]
    m[:, 0, 0], m[:, 1, 0] = 0.1 * MS * m_along, -0.05 * MS * m_along
    return m


def make_hysteresis(directory, positions=None):
    """A 0 -> 100 mT -> -100 mT -> 100 mT loop: the pair snaps into contact above 60 mT and
    separates again below 30 mT."""
    b, _ = sweep(b_max=0.1, step=0.01)
    clustered, state = np.zeros(b.size, bool), False
    for i, value in enumerate(np.abs(b)):
        state = value > 0.06 or (state and value > 0.03)
        clustered[i] = state
    s = np.where(clustered, 2.05 * RADIUS, 5e-6 - 4e-4 * b**2)
    m_along = np.tanh(b / 0.04) * np.where(clustered, 1.0, 0.8)
    n = b.size
    return write_run(directory, "mess_hysteresis", along_z(b), np.arange(n), np.zeros(n),
                     np.zeros(n), "1", -2e3 * m_along * b + 50.0, pair_centres(s),
                     magnetizations(m_along), positions=positions)


def make_magnetostriction(directory, positions="results"):
    b = np.linspace(0.0, 0.1, 11)
    m_along = np.tanh(b / 0.04)
    s = 5e-6 - 1.5e-6 * (b / 0.1) ** 2
    n = b.size
    return write_run(directory, "mess_magnetostriction", along_z(b), np.arange(n),
                     np.zeros(n), np.zeros(n), "1", -2e3 * m_along * b + 50.0, pair_centres(s),
                     magnetizations(m_along), positions=positions)


def make_strain(directory, positions="files", mr_nan=False, invalid_field=None, fields=None):
    """Simple shear 0 .. 0.1 rad at 4 fields (or at `fields`, in T); at the largest field the
    energy density drops at the 8th strain (clustering), so only 7 points are fitted.
    invalid_field: the index of a field whose fit is marked invalid (/analysis/valid = 0, only 2
    points) while its modulus stays a finite number, as mresim writes it."""
    fields = np.array([0.0, 0.02, 0.05, 0.1] if fields is None else fields)
    gammas = np.linspace(0.0, 0.1, 11)
    moduli = 4e3 * (1 + 0.4 * np.arange(fields.size) ** 1.5)
    offsets = -300.0 * fields / 0.1
    f_idx = np.tile(np.arange(fields.size), gammas.size)
    l_idx = np.repeat(np.arange(gammas.size), fields.size)
    gamma = gammas[l_idx]
    strain = np.tan(gamma)
    u = 0.5 * moduli[f_idx] * strain**2 + offsets[f_idx]
    kink = (f_idx == fields.size - 1) & (l_idx >= 7)
    u[kink] -= 8.0
    fit_points = np.array([gammas.size] * (fields.size - 1) + [7])
    m_along = np.tanh(fields[f_idx] / 0.04)
    s = 5e-6 - 1e-6 * (fields[f_idx] / 0.1) ** 2 - 0.3e-6 * gamma
    modulus = moduli.copy()
    mr = (modulus / modulus[0] - 1) * 100
    if mr_nan:
        modulus[0] = np.nan
        mr[:] = np.nan
    valid = np.isfinite(modulus).astype(np.int64)
    problem = [""] * fields.size
    if invalid_field is not None:
        valid[invalid_field] = 0
        fit_points[invalid_field] = 2
        modulus[invalid_field] *= 3.0  # the nonsense value an invalid fit gives
        mr[invalid_field] = (modulus[invalid_field] / modulus[0] - 1) * 100
        problem[invalid_field] = "only 2 point(s) fitted, at least 3 needed"
    mr_valid = valid * valid[0]
    analysis = dict(modulus_name="G_eff", field_magnitude=fields, modulus=modulus,
                    offset=offsets, rms_residual=np.full(fields.size, 1e-3),
                    fit_points=fit_points, split=(fit_points < gammas.size).astype(np.int64),
                    mr_effect=mr, valid=valid, problem=np.array(problem, dtype=object),
                    mr_effect_valid=mr_valid)
    return write_run(directory, "mess_strain", along_z(fields[f_idx]), f_idx, l_idx, gamma, "rad",
                     u, pair_centres(s), magnetizations(m_along), measured_strain=strain,
                     analysis=analysis, positions=positions)


def make_stress(directory, positions=None):
    """Tension 0 .. 100 Pa at 3 fields; the strain follows sigma / E_eff(B)."""
    fields = np.array([0.0, 0.04, 0.08])
    stresses = np.linspace(0.0, 100.0, 6)
    moduli = 9e3 * (1 + 0.25 * np.arange(fields.size))
    f_idx = np.tile(np.arange(fields.size), stresses.size)
    l_idx = np.repeat(np.arange(stresses.size), fields.size)
    sigma = stresses[l_idx]
    strain = sigma / moduli[f_idx] * (1 + 0.02 * np.cos(l_idx))
    u = -0.5 * sigma * strain - 100.0 * fields[f_idx]
    m_along = np.tanh(fields[f_idx] / 0.04)
    s = 5e-6 + strain * 5e-6
    analysis = dict(modulus_name="E_eff (stress)", field_magnitude=fields, modulus=moduli,
                    offset=np.zeros(fields.size), rms_residual=np.full(fields.size, 0.5),
                    fit_points=np.full(fields.size, stresses.size),
                    split=np.zeros(fields.size, dtype=np.int64),
                    mr_effect=(moduli / moduli[0] - 1) * 100)
    return write_run(directory, "mess_stress", along_z(fields[f_idx]), f_idx, l_idx, sigma, "Pa",
                     u, pair_centres(s), magnetizations(m_along), measured_strain=strain,
                     analysis=analysis, positions=positions)


# ---------------------------------------------------------------- datasets of newer runs
# Added to a run directory that a make_* function above wrote, as a newer mresim writes them
# (docs/outputs-3d.md); the figures must draw them when present and skip them when absent.

# Energies with known strain dependence for add_known_energies: per term (value at zero strain
# per field index k, change per unit x^2). "wca", "dipole" and "load" are zero at every step;
# "self" is constant in the strain (nonzero at the fields > 0).
KNOWN_ENERGIES = {
    "springs": (lambda k: 1e-15 * k, 2e-13),
    "volume": (lambda k: 3e-16 * k, -5e-14),
    "zeeman": (lambda k: -4e-13 * k, 1e-13 * 0.5),
    "self": (lambda k: 2e-13 * k, 0.0),
    "self_linearized": (lambda k: 3e-13 * k, 0.0),
    "dipole": (lambda k: 0.0, 0.0),
    "wca": (lambda k: 0.0, 0.0),
    "load": (lambda k: 0.0, 0.0),
}


def add_known_energies(directory):
    """Replaces /steps/energies/* of a strain or stress run by E = E0(k) + slope x^2 (x the
    measured strain, k the field index) per KNOWN_ENERGIES; total the sum (less
    self_linearized). Returns {term: E} as written."""
    written = {}
    with h5py.File(os.path.join(directory, "results.h5"), "a") as f:
        s = f["steps"]
        k = s["field_index"][()].astype(float)
        x = s["measured_strain"][()]
        for name, (e0, slope) in KNOWN_ENERGIES.items():
            values = np.array([e0(v) for v in k]) + slope * x**2
            s[f"energies/{name}"][...] = values
            written[name] = values
        written["total"] = sum(v for n, v in written.items() if n != "self_linearized")
        s["energies/total"][...] = written["total"]
    return written


def add_pair_angle(directory, angles_deg=None):
    """/steps/pair_angle (rad): by default 5 deg per unit of load index plus 2 deg per field
    index, so that every field has its own curve."""
    with h5py.File(os.path.join(directory, "results.h5"), "a") as f:
        s = f["steps"]
        if angles_deg is None:
            angles_deg = 5.0 * s["load_index"][()] + 2.0 * s["field_index"][()]
        s["pair_angle"] = np.radians(np.asarray(angles_deg, dtype=float))
        s["pair_angle"].attrs["unit"] = "rad"
    return np.asarray(angles_deg, dtype=float)


def add_magnetostriction(directory, values=None):
    """/steps/box_strain (S x 3) and /steps/magnetostriction (S, the z component: the fixtures'
    field is along z); by default 2e-3 (B / 0.1 T)^2, the transverse components -half of it."""
    with h5py.File(os.path.join(directory, "results.h5"), "a") as f:
        s = f["steps"]
        b = s["field_projection"][()]
        along = 2e-3 * (b / 0.1) ** 2 if values is None else np.asarray(values, dtype=float)
        s["box_strain"] = np.stack([-0.5 * along, -0.5 * along, along], axis=1)
        s["magnetostriction"] = along
        for name in ("box_strain", "magnetostriction"):
            s[name].attrs["unit"] = "1"
    return along


def add_second_fit(directory, slope=None, form=None):
    """/analysis/second_* of make_strain's run: the last field (index 3) drops by 8 J/m^3 from
    its 8th strain on, so its second fit has the first fit's modulus, offset - 8, first point 7
    and 4 points; the other fields have none (valid 0, NaN). slope: a /analysis/second_slope
    value for field 3 (the u = a x^2/2 + b x + c form); form: a /analysis@second_form text."""
    with h5py.File(os.path.join(directory, "results.h5"), "a") as f:
        a = f["analysis"]
        n = a["modulus"].shape[0]
        last = n - 1
        modulus, offset = np.full(n, np.nan), np.full(n, np.nan)
        modulus[last] = a["modulus"][last]
        offset[last] = a["offset"][last] - 8.0
        first, points = np.zeros(n, dtype=np.int64), np.zeros(n, dtype=np.int64)
        first[last], points[last] = 7, 4
        valid = np.zeros(n, dtype=np.int64)
        valid[last] = 1
        a["second_modulus"], a["second_offset"] = modulus, offset
        a["second_rms_residual"] = np.where(valid > 0, 1e-3, np.nan)
        a["second_first_point"], a["second_fit_points"], a["second_valid"] = first, points, valid
        if slope is not None:
            b = np.full(n, np.nan)
            b[last] = slope
            a["second_slope"] = b
        if form is not None:
            a.attrs["second_form"] = form
    return dict(field=last, modulus=modulus[last], offset=offset[last], first=7, points=4)
