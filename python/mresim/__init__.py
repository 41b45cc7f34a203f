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

import os as _os
from pathlib import Path as _Path


def _find_installed_plot_scripts():
    """An installed package (cmake --install) lies in <prefix>/<python dir>/mresim and the
    plotting scripts in <prefix>/share/mresim/python: found upwards from here, wherever the prefix
    was moved. The build tree's module finds the source tree's scripts without this."""
    for parent in _Path(__file__).resolve().parents:
        scripts = parent / "share" / "mresim" / "python"
        if (scripts / "mresim_plot.py").is_file():
            return str(scripts)
    return None


# The figures of a run are drawn by those scripts (what `mresim run` does); an explicit
# MRESIM_PYTHON_DIR wins.
if not _os.environ.get("MRESIM_PYTHON_DIR") and _find_installed_plot_scripts():
    _os.environ["MRESIM_PYTHON_DIR"] = _find_installed_plot_scripts()

from ._core import ConfigError, OutputDirectoryError, __version__  # noqa: E402
from .results import Group, Results, load  # noqa: E402
from .runs import InvalidResultsError, Run, info, run, run_types  # noqa: E402
from . import pair  # noqa: E402

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
