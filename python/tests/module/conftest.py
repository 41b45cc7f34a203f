"""Shared inputs of the mresim module tests: small run files (milliseconds to a few seconds)
and the `mresim` command line to compare against (MRESIM_BIN, set by CTest)."""

import json
import os
import pathlib
import subprocess

import pytest

SOURCE_DIR = pathlib.Path(os.environ.get("MRESIM_SOURCE_DIR",
                                         pathlib.Path(__file__).resolve().parents[3]))

# A soft single spring (k = 0.01 N/m, S0 = 9 um) along the field: it clusters at 0.39 T and
# separates at 0.11 T; a coarse sweep of 101 steps.
PAIR_TOML = """\
[run]
type = "pair_hysteresis"
title = "single spring, axial"

[springs]
model = "single"
k = 1e-2
rest_separation = 9e-6

[field]
max = 0.5
step = 0.025

[critical_fields]
tolerance = 1e-3
"""

PAIR_DICT = {
    "run": {"type": "pair_hysteresis", "title": "single spring, axial"},
    "springs": {"model": "single", "k": 1e-2, "rest_separation": 9e-6},
    "field": {"max": 0.5, "step": 0.025},
    "critical_fields": {"tolerance": 1e-3},
}

# Two particles along the field in a 1 % cell (one voxel layer around each), 0 -> 100 mT:
# a 3D run of about a second, with node positions.
MESS_DICT = {
    "run": {"type": "mess_hysteresis", "title": "pair along the field", "threads": 1},
    "model": {"profile": "physical", "discretization_order": 1},
    "particles": {
        "radius": 1.5e-6,
        "saturation_magnetization": 1.6e6,
        "susceptibility": 70,
        "placement": "regular",
        "volume_fraction": 0.01,
        "count_per_axis": [1, 1, 2],
    },
    "field": {"max": 0.1, "steps": 1, "theta": 0, "phi": 0, "sequence": "up"},
    "solver": {"method": "minimiser"},
    "output": {"node_positions": True, "checkpoint_every": 0},
}


@pytest.fixture(scope="session")
def mresim_bin():
    binary = os.environ.get("MRESIM_BIN")
    if not binary:
        pytest.fail("MRESIM_BIN (the mresim command to compare with) is not set; run via ctest")
    return binary


@pytest.fixture(scope="session")
def cli(mresim_bin):
    """Runs `mresim ARGS...`; returns the CompletedProcess (text)."""

    def run(*args, cwd=None):
        return subprocess.run([mresim_bin, *map(str, args)], capture_output=True, text=True,
                              cwd=cwd, check=False)

    return run


@pytest.fixture(scope="session")
def cli_info(cli):
    def info(path, *args):
        done = cli("info", "--json", path, *args)
        assert done.returncode == 0, done.stderr
        return json.loads(done.stdout)

    return info
