"""The two-dipole models at single states (mresim.pair) against the library's run of the same
pair (`mresim run`, results.h5) and against their own definitions."""

import h5py
import numpy as np
import pytest

import mresim
from mresim import pair
from conftest import PAIR_DICT, PAIR_TOML


@pytest.fixture(scope="module")
def cli_loop(tmp_path_factory, cli):
    directory = tmp_path_factory.mktemp("pair_cli")
    path = directory / "pair.toml"
    path.write_text(PAIR_TOML)
    done = cli("run", path, "--out", directory / "run", "--no-plot")
    assert done.returncode == 0, done.stderr
    with h5py.File(directory / "run" / "results.h5", "r") as f:
        group = f["cases/0"]
        loop = {name: group[name][()] for name in ("field", "separation", "distance",
                                                   "moment", "magnetization_along_field")}
        loop["energy"] = {name: group["energy"][name][()] for name in group["energy"]}
        loop["critical_fields"] = dict(group["critical_fields"].attrs)
    return loop


@pytest.fixture(scope="module")
def model():
    return pair.Pair(PAIR_DICT)


def test_hysteresis_is_the_run_types_loop(model, cli_loop):
    loop = model.hysteresis()
    for name in ("field", "separation", "distance", "moment", "magnetization_along_field"):
        np.testing.assert_array_equal(loop[name], cli_loop[name], err_msg=name)
    for term, values in cli_loop["energy"].items():
        np.testing.assert_array_equal(loop["energy"][term], values, err_msg=term)


def test_states_of_the_loop_are_reproduced_one_by_one(model, cli_loop):
    i = int(np.argmax(cli_loop["field"]))  # +field.max on the first branch: clustered
    d = cli_loop["separation"][i]
    b = cli_loop["field"][i]
    energy = model.energy(d, b)
    for term, values in cli_loop["energy"].items():
        assert energy[term] == pytest.approx(values[i], rel=1e-12, abs=1e-30), term
    moment, saturated = model.magnetization(d, b)
    np.testing.assert_allclose(moment, cli_loop["moment"][i], rtol=1e-12)
    assert isinstance(saturated, bool)
    state = model.relax(b, start=cli_loop["separation"][i - 1])
    assert state["distance"] == pytest.approx(cli_loop["distance"][i], rel=1e-9)
    assert state["converged"]


def test_critical_fields_are_the_run_types(model, cli_loop):
    # The run type refines from the whole loop, this from the first quadrant (as a pair_map
    # point does): the same bracket to within the tolerance.
    fields = model.critical_fields()
    expected = cli_loop["critical_fields"]
    assert fields["hysteresis"] and fields["valid"]
    assert fields["HC2"] == pytest.approx(expected["HC2_T"], abs=1e-3)
    assert fields["HC1"] == pytest.approx(expected["HC1_T"], abs=1e-3)
    assert fields["dH"] == pytest.approx(fields["HC2"] - fields["HC1"])


def test_gradient_is_the_derivative_of_the_energy(model):
    d = np.array([7.5e-6, 0.4e-6, -0.3e-6])
    b = 0.3
    gradient = model.gradient(d, b)
    h = 1e-11
    for axis in range(3):
        step = np.zeros(3)
        step[axis] = h
        numeric = (model.energy(d + step, b)["total"] - model.energy(d - step, b)["total"]) / (2 * h)
        assert gradient[axis] == pytest.approx(numeric, rel=1e-5, abs=1e-12 * abs(gradient).max())


def test_arrays_of_states(model):
    distances = np.linspace(4e-6, 9e-6, 5)
    energies = model.energy(distances, 0.2)
    assert energies["total"].shape == (5,)
    np.testing.assert_allclose(
        sum(energies[t] for t in ("zeeman", "dipole", "self", "spring", "anchor", "penalty")),
        energies["total"], rtol=1e-12)
    vectors = np.column_stack([distances, np.zeros(5), np.zeros(5)])
    np.testing.assert_array_equal(model.energy(vectors, 0.2)["total"], energies["total"])
    assert model.gradient(vectors, [0.2, 0, 0]).shape == (5, 3)
    moments, saturated = model.magnetization(distances, 0.2)
    assert moments.shape == (5, 3) and saturated.dtype == bool


def test_thresholds_are_the_info_reports(model):
    info = mresim.info(PAIR_DICT)
    section = next(s for s in info.values() if "clustering_threshold_S0" in s)
    assert model.clustering_threshold_separation() == section["clustering_threshold_S0"]["value"]
    assert pair.clustering_threshold_stiffness(9e-6) == section["clustering_threshold_k"]["value"]
    # Eq. 2.10 and its inverse agree.
    s0 = pair.clustering_threshold_separation(0.04)
    assert pair.clustering_threshold_stiffness(s0) == pytest.approx(0.04, rel=1e-12)


def test_pair_from_keywords_and_cases():
    p = pair.Pair(springs={"model": "three", "k0": 0.02, "k12": 0.03}, field={"angle": 30})
    assert p.parameters["spring_model"] == "three" and p.parameters["penalty"] == "wca"
    np.testing.assert_allclose(p.field_vector(1.0),
                               [np.cos(np.radians(30)), 0, np.sin(np.radians(30))])
    cases = dict(PAIR_DICT, case=[{"label": "soft", "springs": {"k": 0.01}},
                                  {"label": "stiff", "springs": {"k": 0.9}}])
    assert pair.Pair(cases, case="stiff").parameters["k12"] == 0.9
    assert pair.Pair(cases, case=0).parameters["k12"] == 0.01
    with pytest.raises(mresim.ConfigError, match="choose one with case="):
        pair.Pair(cases)


def test_pair_errors_are_the_run_files():
    with pytest.raises(mresim.ConfigError, match=r"^springs\.k = -1: must be > 0"):
        pair.Pair(springs={"k": -1})
    with pytest.raises(mresim.ConfigError, match="unknown key 'springs.kk'"):
        pair.Pair(springs={"k": 1, "kk": 1})
