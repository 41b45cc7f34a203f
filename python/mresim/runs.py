"""Validating, describing and running run files (`mresim info`, `mresim run`)."""

import json
import math
import os
import shutil
import tempfile
import threading
import tomllib
import warnings

from . import _core
from .results import load

# Runs in one process take turns: each uses every core it is given (OpenMP threads are a
# process-wide setting) and installs the process's SIGINT/SIGTERM handlers while it computes.
_one_run_at_a_time = threading.Lock()


class InvalidResultsError(RuntimeError):
    """The run finished and wrote its results, but some are non-finite or unconverged.

    `mresim run` publishes such a run with the bad entries marked and exits with status 4; here
    the message is the command line's and the results are kept in :attr:`results` (their
    ``valid`` datasets say which entries are bad).
    """

    def __init__(self, results):
        super().__init__(results.invalid_results)
        self.results = results


def _toml_value(value):
    """A Python value as TOML text, for overrides given as a dict."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if math.isnan(value):
            return "nan"
        if math.isinf(value):
            return "inf" if value > 0 else "-inf"
        return repr(value)
    if isinstance(value, str):
        return json.dumps(value)  # a TOML basic string
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_toml_value(v) for v in value) + "]"
    if hasattr(value, "tolist"):  # numpy scalars and arrays
        return _toml_value(value.tolist())
    raise TypeError(f"override value {value!r}: use a number, string, boolean or list")


def _override_arguments(overrides):
    """`--set` arguments from a list of "KEY=VALUE" strings or a dict {KEY: value}."""
    if overrides is None:
        return []
    if isinstance(overrides, str):
        return [overrides]
    if hasattr(overrides, "items"):
        return [f"{key}={_toml_value(value)}" for key, value in overrides.items()]
    return [str(o) for o in overrides]


def _thread_count(threads):
    """-1 (take [run].threads) or a count the command line's --threads accepts."""
    if threads is None:
        return -1
    if isinstance(threads, bool) or not isinstance(threads, int) or not (
        0 <= threads <= _core.max_threads()
    ):
        raise ValueError(f"threads = {threads!r}: {_core.threads_allowed()}")
    return threads


class Run:
    """A run file, read and validated completely (unknown keys included) on construction.

    ``config`` is a dict of tables (``{"run": {"type": ...}, "field": {...}}``), TOML text
    (``str``) or the path of a run file (``pathlib.Path`` or any ``os.PathLike``; a plain
    ``str`` is always TOML text). ``overrides`` are applied first, exactly as ``mresim run
    --set KEY=VALUE``: a list of ``"KEY=VALUE"`` strings or a dict ``{"field.max": 0.2}``.

    Raises :class:`mresim.ConfigError` with the command line's one-line message for anything
    wrong in the file.
    """

    def __init__(self, config, overrides=None):
        self._plan = _core.RunPlan(config, _override_arguments(overrides))

    @property
    def run_type(self):
        """``[run].type``."""
        return self._plan.run_type

    @property
    def toml(self):
        """The run file that is validated and run (with overrides: as toml++ writes it)."""
        return self._plan.toml

    @property
    def config(self):
        """The run file as a dict of tables (parsed from :attr:`toml`)."""
        return tomllib.loads(self._plan.toml)

    def info(self):
        """Every derived quantity, as ``mresim info --json`` prints it:
        ``{section: {key: {"value": ..., "unit": ..., "note": ...}}}``."""
        return json.loads(self._plan.info_json())

    def run(self, out=None, *, threads=None, force=False, plot=False, check=True):
        """Computes the run and returns its :class:`~mresim.Results`.

        out:     the run directory (created; an earlier mresim run there is replaced, any
                 other existing directory refused with OutputDirectoryError unless ``force``,
                 which moves it aside). None: a temporary directory, removed when the
                 returned results are garbage-collected (``results.path`` while they live).
        threads: OpenMP threads, 0 = all cores; None takes ``[run].threads``. Results do not
                 depend on it.
        plot:    also draw ``figures/*.png`` as ``mresim run`` does (needs matplotlib).
        check:   raise :class:`InvalidResultsError` (results attached) when some results are
                 non-finite or unconverged; with False, look at ``results.invalid_results``.

        The computation releases the GIL; runs started from several Python threads take
        turns. Ctrl-C (or a notebook's interrupt) stops it at its
        next safe point, as on the command line, and raises KeyboardInterrupt; a 3D run then
        keeps its checkpoint in ``out`` for ``mresim resume`` (or, stopped during its last
        step, its complete results, without figures; the message says which).
        """
        thread_count = _thread_count(threads)
        temporary = None
        if out is None:
            temporary = tempfile.mkdtemp(prefix="mresim-")
            out = os.path.join(temporary, "run")
        out = os.fspath(out)
        try:
            with _one_run_at_a_time:
                status, published = self._plan.execute(out, thread_count, bool(force), bool(plot))
            if status >= 128:
                if published:  # the signal came during a 3D run's last step
                    where = (
                        "the results were complete (temporary directory, removed)"
                        if temporary
                        else f"it came after the last step: the results are complete in '{out}'"
                    )
                else:
                    where = (
                        "nothing was kept (temporary directory)"
                        if temporary
                        else f"continue a 3D run with 'mresim resume {out}'"
                    )
                raise KeyboardInterrupt(f"mresim: the run was stopped by signal {status - 128}; {where}")
            results = load(out)
        except BaseException:
            if temporary:
                shutil.rmtree(temporary, ignore_errors=True)
            raise
        if temporary:
            results._remove_when_collected(temporary)
        if status == _core.EXIT_PLOT_FAILED:
            warnings.warn(f"drawing the figures failed; the results are complete in '{out}'",
                          RuntimeWarning, stacklevel=2)
        if check and results.invalid_results:
            raise InvalidResultsError(results)
        return results

    def __repr__(self):
        return f"mresim.Run({self.run_type!r}, source={self._plan.source_name!r})"


def info(config, overrides=None):
    """``Run(config, overrides).info()``: validate and derive without running."""
    return Run(config, overrides).info()


def run(config, out=None, *, overrides=None, threads=None, force=False, plot=False, check=True):
    """``Run(config, overrides).run(out, ...)``: validate, compute, return the results."""
    return Run(config, overrides).run(out, threads=threads, force=force, plot=plot, check=check)


def run_types():
    """{name: one-line summary} of the run types in this build (``mresim types``)."""
    return dict(_core.run_types())
