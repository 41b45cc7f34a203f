"""A finished run directory as numpy arrays (results.h5 and the CSV tables beside it).

The layout of results.h5 is documented per run type in docs/run-files.md (two-dipole and
single-particle runs) and docs/outputs-3d.md (3D runs); :class:`Results` reads it generically,
so datasets a later version adds are there too, and adds named shortcuts for what most analyses
need.
"""

import csv
import os
import re
import shutil
import tomllib
import weakref
from collections.abc import Mapping

import h5py
import numpy as np

RESULTS_FILE = "results.h5"


def _decoded(value):
    """HDF5 attribute values as Python values (str for strings, numbers as numpy scalars)."""
    if isinstance(value, bytes):
        return value.decode("utf-8")
    if isinstance(value, np.ndarray) and value.dtype.kind in "SO":
        return np.array([_decoded(v) for v in value.ravel()], dtype=object).reshape(value.shape)
    return value


def _read_dataset(dataset):
    if dataset.dtype.kind in "SO":  # strings: str, not bytes
        return np.asarray(dataset.asstr()[()], dtype=object)
    return dataset[()]


class Group(Mapping):
    """An HDF5 group read into memory: a read-only mapping of names to numpy arrays and
    sub-groups, also reachable as attributes (``steps.energies.total``); the group's HDF5
    attributes are in :attr:`attrs`."""

    def __init__(self, group):
        self.name = group.name
        self.attrs = {key: _decoded(value) for key, value in group.attrs.items()}
        self._items = {}
        for key, item in group.items():
            if isinstance(item, h5py.Group):
                self._items[key] = Group(item)
            elif isinstance(item, h5py.Dataset):
                self._items[key] = _read_dataset(item)

    def __getitem__(self, key):
        node = self
        for part in key.strip("/").split("/"):
            if not isinstance(node, Group):
                raise KeyError(key)
            node = node._items[part]
        return node

    def __iter__(self):
        return iter(self._items)

    def __len__(self):
        return len(self._items)

    def __getattr__(self, name):
        try:
            return self.__dict__["_items"][name]
        except KeyError:
            raise AttributeError(f"{self.name} has no dataset or group '{name}'") from None

    def __dir__(self):
        return list(super().__dir__()) + list(self._items)

    def __repr__(self):
        return f"<mresim.Group {self.name}: {', '.join(self._items)}>"


def _step_number(name):
    match = re.fullmatch(r"step_(\d+)(\.h5)?", name)
    return int(match.group(1)) if match else None


class Results:
    """The results of one run directory, as ``mresim.run`` returns them and ``mresim.load``
    opens them.

    Generic access: ``results["steps/energies/total"]`` (any dataset or group of results.h5),
    ``results.attrs`` (root attributes), ``results.h5()`` (an open h5py.File for anything
    else), ``results.table("summary.csv")``.

    Shortcuts (None where the run type has no such output):

    - every run: ``run_type``, ``title``, ``config`` (the run file that ran, as a dict),
      ``input_toml``, ``valid`` / ``invalid_results``, ``warnings``;
    - 3D runs (``mess_*``, docs/outputs-3d.md): ``steps``, ``lattice``, ``analysis``,
      ``field`` (S x 3, T), ``loads`` (S), ``energies`` ({term: S}, J), ``centres`` (S x N_p x 3, m),
      ``magnetization`` (S x N_p x 3, A/m), ``moduli`` (the ``/analysis`` fits),
      ``positions(step)`` / ``node_positions`` (with ``[output] node_positions = true``);
    - two-dipole runs: ``cases`` (one Group per case, ``/cases/<i>``, with its
      ``critical_fields`` attributes), ``map`` (``pair_map``);
    - single-particle runs: ``curve``.
    """

    def __init__(self, path):
        self.path = os.fspath(path)
        self.file = os.path.join(self.path, RESULTS_FILE)
        if not os.path.isfile(self.file):
            raise FileNotFoundError(
                f"'{self.path}' is not an mresim run directory: it has no {RESULTS_FILE}")
        with h5py.File(self.file, "r") as f:
            self.attrs = {key: _decoded(value) for key, value in f.attrs.items()}
            self._top = {key: isinstance(item, h5py.Group) for key, item in f.items()}
        self._groups = {}

    # --- generic access ---------------------------------------------------------------------

    def h5(self):
        """results.h5 opened read-only (use as a context manager)."""
        return h5py.File(self.file, "r")

    def __getitem__(self, key):
        """A dataset (numpy array) or group (:class:`Group`) of results.h5 by its path."""
        top, _, rest = key.strip("/").partition("/")
        group = self._group(top)
        if group is None:
            with self.h5() as f:
                return _read_dataset(f[key])
        return group[rest] if rest else group

    def __contains__(self, key):
        with self.h5() as f:
            return key in f

    def keys(self):
        """The top-level groups and datasets of results.h5."""
        return list(self._top)

    def _group(self, name):
        """The top-level group `name` read into memory once, or None if it is not a group."""
        if not self._top.get(name):
            return None
        if name not in self._groups:
            with self.h5() as f:
                self._groups[name] = Group(f[name])
        return self._groups[name]

    def table(self, name="summary.csv"):
        """A CSV table of the run directory as {column: numpy array} (numbers as float, other
        columns as str)."""
        with open(os.path.join(self.path, name), newline="", encoding="utf-8") as handle:
            rows = list(csv.reader(handle))
        header, body = rows[0], rows[1:]
        columns = {}
        for i, column in enumerate(header):
            values = [row[i] for row in body]
            try:
                columns[column] = np.array([float(v) for v in values])
            except ValueError:
                columns[column] = np.array(values, dtype=object)
        return columns

    # --- every run ----------------------------------------------------------------------------

    @property
    def run_type(self):
        return self.attrs.get("run_type")

    @property
    def title(self):
        return self.attrs.get("title", "")

    @property
    def input_toml(self):
        """The run file that ran, byte for byte (with overrides: the effective file)."""
        return self.attrs.get("input_toml", "")

    @property
    def config(self):
        """The run file that ran, as a dict of tables."""
        return tomllib.loads(self.input_toml)

    @property
    def invalid_results(self):
        """`mresim run`'s message about non-finite or unconverged results ("" when none)."""
        return self.attrs.get("invalid_results", "")

    @property
    def valid(self):
        return not self.invalid_results

    @property
    def warnings(self):
        """The run's warnings (``mresim: warning: ...`` lines), one string each."""
        text = self.attrs.get("warnings", "")
        return [line for line in text.splitlines() if line]

    # --- 3D runs --------------------------------------------------------------------------------

    @property
    def steps(self):
        return self._group("steps")

    @property
    def lattice(self):
        return self._group("lattice")

    @property
    def analysis(self):
        return self._group("analysis")

    moduli = analysis

    def _step_dataset(self, name):
        steps = self.steps
        return None if steps is None or name not in steps else steps[name]

    @property
    def field(self):
        """Applied field B = mu0 H of every step (S x 3, T)."""
        return self._step_dataset("field")

    @property
    def loads(self):
        """Applied load of every step (S: shear angle in rad, strain, twist angle or stress in
        Pa, see ``steps.attrs``/docs/outputs-3d.md); ``steps["measured_strain"]`` is the strain
        the moduli are fitted against."""
        return self._step_dataset("load_value")

    @property
    def energies(self):
        """{term: energy of every step (J)}, the terms of ``/steps/energies``."""
        group = self._step_dataset("energies")
        return None if group is None else dict(group)

    @property
    def centres(self):
        """Particle centres of every step (S x N_p x 3, m)."""
        return self._step_dataset("centres")

    @property
    def magnetization(self):
        """Particle magnetizations of every step (S x N_p x 3, A/m)."""
        return self._step_dataset("magnetization")

    def position_steps(self):
        """The steps whose node positions were saved, in order."""
        steps = set()
        with self.h5() as f:
            if isinstance(f.get("positions"), h5py.Group):
                steps.update(n for n in map(_step_number, f["positions"]) if n is not None)
        directory = os.path.join(self.path, "positions")
        if os.path.isdir(directory):
            steps.update(n for n in map(_step_number, os.listdir(directory)) if n is not None)
        return sorted(steps)

    def positions(self, step):
        """Node positions of one step (N x 3, m); None if they were not saved. Read from
        ``positions/step_NNNNNN.h5`` (what mresim writes) or ``/positions/step_NNNNNN`` in
        results.h5."""
        name = f"step_{step:06d}"
        with self.h5() as f:
            if isinstance(f.get("positions"), h5py.Group) and name in f["positions"]:
                return np.asarray(f["positions"][name][()], dtype=float)
        file = os.path.join(self.path, "positions", name + ".h5")
        if os.path.isfile(file):
            with h5py.File(file, "r") as g:
                return np.asarray(g["positions"][()], dtype=float)
        return None

    @property
    def node_positions(self):
        """Node positions of every saved step (len(position_steps()) x N x 3, m), or None."""
        steps = self.position_steps()
        return np.stack([self.positions(s) for s in steps]) if steps else None

    # --- two-dipole and single-particle runs ---------------------------------------------------

    @property
    def cases(self):
        """One Group per loop or ensemble (``/cases/<i>``), in case order."""
        group = self._group("cases")
        if group is None:
            return None
        return [group[str(i)] for i in sorted(int(k) for k in group)]

    @property
    def map(self):
        return self._group("map")

    @property
    def curve(self):
        return self._group("curve")

    # --- housekeeping ----------------------------------------------------------------------------

    def _remove_when_collected(self, directory):
        """Removes `directory` (a temporary run's) when these results are garbage-collected."""
        self._temporary = weakref.finalize(self, shutil.rmtree, directory, True)

    def __repr__(self):
        state = "valid" if self.valid else "INVALID"
        return f"<mresim.Results {self.run_type} in {self.path!r} ({state})>"


def load(path):
    """Opens a finished run directory (from ``mresim run`` or :func:`mresim.run`)."""
    return Results(path)
