"""mresim from Python: run files in, numpy arrays out.

A run is described as on the command line (docs/run-files.md, docs/run-files-3d.md), as a dict
of tables, as TOML text or as a path to a run file::

    import mresim

    config = {
        "run": {"type": "pair_hysteresis", "title": "single spring"},
        "springs": {"k": 0.04, "rest_separation": 9e-6},
        "field": {"max": 0.5, "step": 0.01},
    }
    mresim.info(config)["pair"]["clustering_threshold_S0"]   # what `mresim info` derives
    results = mresim.run(config)                  # into a temporary run directory
    loop = results.cases[0]
    loop["field"], loop["magnetization_along_field"]          # numpy arrays

    results = mresim.load("runs/fig2_2")          # a finished run directory

The two-dipole models at single states are in :mod:`mresim.pair`. Bad input raises
:class:`ConfigError` (a ValueError) with the message `mresim` prints. docs/python.md has the
whole API.
"""

from ._core import ConfigError, OutputDirectoryError, __version__
from .results import Group, Results, load
from .runs import InvalidResultsError, Run, info, run, run_types
from . import pair

__all__ = [
    "ConfigError",
    "Group",
    "InvalidResultsError",
    "OutputDirectoryError",
    "Results",
    "Run",
    "__version__",
    "info",
    "load",
    "pair",
    "run",
    "run_types",
]
