"""mresim.run writes the run directory `mresim run` writes; load() reads it back; both give the
arrays of the command line's results.h5 for the same run file."""

import h5py
import numpy as np
import pytest

import mresim
from conftest import MESS_DICT, PAIR_TOML

# Differ from run to run by design: when and how long, not what.
RUN_DEPENDENT = {"created_utc", "wall_time", "input_file", "command_line",
                 "peak_resident_memory_bytes", "peak_resident_memory_bytes_per_node",
                 "peak_resident_memory"}


def h5_contents(path):
    """{name: array or attribute value} of every dataset and attribute of a results.h5."""
    contents = {}
    with h5py.File(path, "r") as f:
        def visit(name, item):
            if name.split("/")[-1] in RUN_DEPENDENT:
                return
            if isinstance(item, h5py.Dataset):
                contents[name] = item[()]
            for key, value in item.attrs.items():
                if key not in RUN_DEPENDENT:
                    contents[f"{name}@{key}"] = value

        visit("", f)
        f.visititems(visit)
    return contents


def assert_same_contents(a, b):
    assert sorted(a) == sorted(b)
    for name in a:
        np.testing.assert_array_equal(a[name], b[name], err_msg=name)


@pytest.fixture(scope="module")
def pair_runs(tmp_path_factory, cli):
    """The pair run file run from Python and from the command line."""
    directory = tmp_path_factory.mktemp("pair")
    path = directory / "pair.toml"
    path.write_text(PAIR_TOML)
    results = mresim.run(path, directory / "python")
    done = cli("run", path, "--out", directory / "cli", "--no-plot")
    assert done.returncode == 0, done.stderr
    return results, directory / "cli"


def test_pair_run_equals_the_command_lines(pair_runs):
    results, cli_dir = pair_runs
    assert_same_contents(h5_contents(results.file), h5_contents(cli_dir / "results.h5"))
    assert (cli_dir / "summary.csv").read_text() == open(results.path + "/summary.csv").read()


def test_pair_results_as_arrays(pair_runs):
    results, cli_dir = pair_runs
    assert results.run_type == "pair_hysteresis" and results.valid
    loop = results.cases[0]
    with h5py.File(cli_dir / "results.h5", "r") as f:
        np.testing.assert_array_equal(loop["separation"], f["cases/0/separation"][()])
        np.testing.assert_array_equal(loop.energy.zeeman, f["cases/0/energy/zeeman"][()])
        assert loop.critical_fields.attrs["HC2_T"] == f["cases/0/critical_fields"].attrs["HC2_T"]
    assert loop.attrs["label"] == "single spring, axial"
    np.testing.assert_allclose(results.table()["B_T"], loop["field"], rtol=1e-9, atol=1e-12)
    assert results.config["springs"]["k"] == 1e-2


def test_load_gives_the_same_results(pair_runs):
    results, _ = pair_runs
    again = mresim.load(results.path)
    assert again.attrs == results.attrs
    np.testing.assert_array_equal(again["cases/0/distance"], results.cases[0].distance)


@pytest.fixture(scope="module")
def mess_runs(tmp_path_factory, cli):
    """A small 3D run from Python (a dict) and from the command line (its TOML)."""
    directory = tmp_path_factory.mktemp("mess")
    run = mresim.Run(MESS_DICT)
    (directory / "mess.toml").write_text(run.toml)
    results = run.run(directory / "python", threads=1)
    done = cli("run", directory / "mess.toml", "--out", directory / "cli", "--no-plot",
               "--threads", "1")
    assert done.returncode == 0, done.stderr
    return results, directory / "cli"


def test_3d_run_equals_the_command_lines(mess_runs):
    results, cli_dir = mess_runs
    assert_same_contents(h5_contents(results.file), h5_contents(cli_dir / "results.h5"))
    cli_results = mresim.load(cli_dir)
    for step in results.position_steps():
        np.testing.assert_array_equal(results.positions(step), cli_results.positions(step))


def test_3d_results_as_arrays(mess_runs):
    results, _ = mess_runs
    steps = len(results.steps["index"])
    particles = len(results.lattice["initial_centres"])
    assert results.run_type == "mess_hysteresis" and particles == 2 and steps == 2
    assert results.centres.shape == (steps, particles, 3)
    assert results.magnetization.shape == (steps, particles, 3)
    assert results.field.shape == (steps, 3)
    np.testing.assert_array_equal(results.loads, np.zeros(steps))  # a field loop: no load
    assert set(results.energies) >= {"springs", "volume", "zeeman", "dipole", "total"}
    np.testing.assert_array_equal(results.energies["total"], results["steps/energies/total"])
    nodes = int(results.lattice.attrs["node_count"])
    assert results.position_steps() == list(range(steps))
    assert results.node_positions.shape == (steps, nodes, 3)
    # At zero field nothing moves: the lattice is where it started.
    np.testing.assert_allclose(results.positions(0), results.lattice["initial_positions"],
                               atol=1e-12)
    # At 100 mT the pair along the field draws together.
    separation = results.steps["separation"]
    assert separation[1] < separation[0]
    assert results.steps.solver.status[0] == "converged"


def test_temporary_run_directory_goes_with_its_results():
    import gc
    import os

    results = mresim.run(PAIR_TOML)
    path = results.path
    assert os.path.isfile(os.path.join(path, "results.h5"))
    del results
    gc.collect()
    assert not os.path.exists(path)


def test_invalid_results_raise_with_the_results_attached(tmp_path, cli):
    # One minimiser iteration cannot relax the 100 mT step: unconverged, status 4 on the CLI.
    overrides = ["solver.minimiser.max_iterations=1"]
    with pytest.raises(mresim.InvalidResultsError) as raised:
        mresim.run(MESS_DICT, tmp_path / "python", overrides=overrides)
    results = raised.value.results
    assert not results.valid
    assert list(results.steps["valid"]) == [1, 0]
    (tmp_path / "mess.toml").write_text(mresim.Run(MESS_DICT).toml)
    done = cli("run", tmp_path / "mess.toml", "--out", tmp_path / "cli", "--no-plot",
               "--set", overrides[0])
    assert done.returncode == 4
    assert f"mresim: error: {raised.value};" in done.stderr
    # check=False returns them instead.
    assert not mresim.run(MESS_DICT, overrides=overrides, check=False).valid


def test_python_signal_handlers_are_back_after_a_run():
    import signal

    before = signal.getsignal(signal.SIGINT)
    mresim.run(PAIR_TOML)
    assert signal.getsignal(signal.SIGINT) is before


def test_runs_from_two_threads_give_the_same_results():
    import threading

    results = [None, None]

    def run(i):
        results[i] = mresim.run(PAIR_TOML).cases[0]["distance"]

    threads = [threading.Thread(target=run, args=(i,)) for i in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert results[0] is not None and results[1] is not None  # neither thread failed
    np.testing.assert_array_equal(results[0], results[1])



def test_the_gil_is_released_while_a_run_computes(tmp_path):
    import threading
    import time

    plan = mresim.Run(MESS_DICT)._plan
    stamps, stop = [], threading.Event()

    def spin():  # needs the GIL for every sample it takes
        while not stop.is_set():
            stamps.append(time.perf_counter())
            time.sleep(0.001)

    spinner = threading.Thread(target=spin)
    spinner.start()
    time.sleep(0.01)
    start = time.perf_counter()
    assert plan.execute(str(tmp_path / "run"), 1, False, False) == (0, True)
    # Taken after this thread has the GIL back: a spinner that only got it after the run
    # returned has samples just before `end`, none in the run's first half.
    end = time.perf_counter()
    stop.set()
    spinner.join()
    assert any(start < s < start + 0.5 * (end - start) for s in stamps)
