"""The standard views of a 3D run's results (docs/outputs-3d.md, "H5MD" and "XDMF"), read by
the tools MRE researchers use, on two small runs made with the mresim binary (MRESIM_BIN, as in
test_plots.py): a hysteresis loop and a shear run, both with node positions.

- H5MD: MDAnalysis' H5MD reader opens results.h5; its positions per frame are /steps/centres,
  its time the step index, its observables the /steps values; the layout has the required
  groups and attributes.
- XDMF: every file parses, every HDF5 dataset it names exists with the shape it states, and
  the leg files' time values are the applied field (hysteresis) or strain (shear).

    MRESIM_BIN=build/mresim /usr/bin/python3 -m unittest discover -v -s python/tests \
        -p test_standard_outputs.py
"""

import glob
import os
import shutil
import subprocess
import tempfile
import unittest
import xml.etree.ElementTree as ET

import h5py
import numpy as np

MODEL = """
[model]
profile = "physical"
discretization_order = 1

[particles]
placement = "chain"
count = 2
separation = 7e-6
axis = "z"

[box]
size = [7e-6, 7e-6, 15e-6]
"""

# 0 -> 50 -> -50 -> 50 mT in 50 mT steps: 6 relaxations, legs [0, 50], [0, -50], [0, 50].
HYSTERESIS = """[run]
type = "mess_hysteresis"
""" + MODEL + """
[field]
max = 0.05
steps = 1

[output]
node_positions = true
checkpoint_every = 0
"""

# 2 fields x 2 shear angles: steps (0 rad, 0 T), (0 rad, 0.05 T), (0.02 rad, 0 T), (0.02 rad,
# 0.05 T); one leg per field with the strain as time.
SHEAR = """[run]
type = "mess_strain"
""" + MODEL + """
[field]
magnitudes = [0.0, 0.05]

[strain]
kind = "shear"
boundary = "all_faces"
max = 0.02
steps = 1

[output]
node_positions = true
checkpoint_every = 0
"""


def find_mresim():
    binary = os.environ.get("MRESIM_BIN", "")
    return binary if binary and os.access(binary, os.X_OK) else None


def run_mresim(binary, toml_text, workdir, name):
    toml = os.path.join(workdir, name + ".toml")
    with open(toml, "w") as f:
        f.write(toml_text)
    out = os.path.join(workdir, name)
    result = subprocess.run([binary, "run", toml, "--out", out, "--threads", "1", "--no-plot"],
                            capture_output=True, text=True, timeout=120)
    if result.returncode != 0:
        raise AssertionError(f"mresim run {name} failed ({result.returncode}): {result.stderr}")
    return out


class _Runs:
    """Both runs, made once for all tests of this module."""
    workdir = None
    dirs = {}

    @classmethod
    def get(cls, binary):
        if cls.workdir is None:
            cls.workdir = tempfile.mkdtemp(prefix="mresim-standard-outputs-")
            cls.dirs = {"hysteresis": run_mresim(binary, HYSTERESIS, cls.workdir, "hysteresis"),
                        "shear": run_mresim(binary, SHEAR, cls.workdir, "shear")}
        return cls.dirs


def tearDownModule():
    if _Runs.workdir is not None:
        shutil.rmtree(_Runs.workdir, ignore_errors=True)


@unittest.skipUnless(find_mresim(), "set MRESIM_BIN=path/to/mresim to check the standard outputs")
class H5mdTest(unittest.TestCase):
    def setUp(self):
        self.dirs = _Runs.get(find_mresim())

    def test_layout_follows_h5md_1_1(self):
        for name, run in self.dirs.items():
            with self.subTest(run=name), h5py.File(os.path.join(run, "results.h5"), "r") as f:
                self.assertEqual(list(f["h5md"].attrs["version"]), [1, 1])
                self.assertTrue(f["h5md/author"].attrs["name"])
                self.assertEqual(f["h5md/creator"].attrs["name"], "mresim")
                self.assertEqual(f["h5md/creator"].attrs["version"], f.attrs["mresim_version"])
                group = f["particles/magnetic_particles"]
                self.assertEqual(group["box"].attrs["dimension"], 3)
                self.assertEqual([str(b) for b in group["box"].attrs["boundary"]],
                                 ["none"] * 3)
                steps = f["steps/index"][()]
                for element in ("position", "magnetization"):
                    self.assertEqual(list(group[element]["step"][()]), list(steps))
                    self.assertEqual(list(group[element]["time"][()]), list(steps.astype(float)))
                self.assertEqual(group["position/value"].attrs["unit"], "nm")
                np.testing.assert_allclose(group["position/value"][()] * 1e-9,
                                           f["steps/centres"][()], rtol=1e-15)
                np.testing.assert_array_equal(group["magnetization/value"][()],
                                              f["steps/magnetization"][()])
                # The node trajectory: a virtual dataset over positions/step_NNNNNN.h5.
                nodes = f["particles/nodes/position/value"]
                self.assertEqual(nodes.shape, (steps.size,) + f["lattice/initial_positions"].shape)
                last = os.path.join(run, "positions", f"step_{steps[-1]:06d}.h5")
                with h5py.File(last, "r") as g:
                    np.testing.assert_array_equal(nodes[-1], g["positions"][()])
                np.testing.assert_array_equal(f["observables/field/value"][()],
                                              f["steps/field"][()])
                self.assertEqual(f["observables/field/value"].attrs["unit"], "T")
                np.testing.assert_array_equal(f["observables/energy_total/value"][()],
                                              f["steps/energies/total"][()])
                np.testing.assert_array_equal(f["parameters/box_lengths"][()],
                                              f["lattice/box_lengths"][()])

    def test_mdanalysis_reads_the_particle_trajectory(self):
        try:
            import MDAnalysis as mda
        except ImportError:
            self.skipTest("MDAnalysis is not installed (Debian: python3-mdanalysis)")
        for name, run in self.dirs.items():
            path = os.path.join(run, "results.h5")
            with self.subTest(run=name), h5py.File(path, "r") as f:
                centres = f["steps/centres"][()]
                field = f["steps/field"][()]
                steps = f["steps/index"][()]
                u = mda.Universe.empty(centres.shape[1], trajectory=True)
                # Quasi-static steps have no physical time: open without unit conversion, so
                # positions stay in the file's nm.
                u.load_new(path, format="H5MD", convert_units=False)
                self.assertEqual(len(u.trajectory), centres.shape[0])
                for ts in u.trajectory:
                    np.testing.assert_allclose(ts.positions * 1e-9, centres[ts.frame], rtol=1e-6)
                    self.assertEqual(ts.time, steps[ts.frame])
                    self.assertEqual(ts.data["step"], steps[ts.frame])
                    np.testing.assert_array_equal(ts.data["field"], field[ts.frame])
                u.trajectory.close()


def hdf_source(xdmf_path, text):
    file_part, dataset = text.strip().split(":", 1)
    return os.path.join(os.path.dirname(xdmf_path), file_part), dataset


def dims(item):
    return tuple(int(d) for d in item.get("Dimensions").split())


@unittest.skipUnless(find_mresim(), "set MRESIM_BIN=path/to/mresim to check the standard outputs")
class XdmfTest(unittest.TestCase):
    def setUp(self):
        self.dirs = _Runs.get(find_mresim())

    def check_file(self, path):
        """Every HDF DataItem names an existing dataset of its stated shape; every hyperslab
        selects inside its source. Returns the grids' time values."""
        root = ET.parse(path).getroot()
        for item in root.iter("DataItem"):
            if item.get("Format") == "HDF":
                file_name, dataset = hdf_source(path, item.text)
                self.assertTrue(os.path.exists(file_name), file_name)
                with h5py.File(file_name, "r") as f:
                    self.assertIn(dataset, f, f"{path}: {file_name}:{dataset}")
                    self.assertEqual(f[dataset].shape, dims(item), f"{path}: {dataset}")
            if item.get("ItemType") == "HyperSlab":
                selection, source = list(item)
                start, stride, count = np.array(selection.text.split(), dtype=int).reshape(3, -1)
                self.assertEqual(tuple(count), dims(item))
                self.assertTrue(np.all(start + (count - 1) * stride < np.array(dims(source))))
        times = []
        for grid in root.iter("Grid"):
            if grid.get("GridType") != "Uniform":
                continue
            times.append(float(grid.find("Time").get("Value")))
            names = {a.get("Name"): a.get("Center") for a in grid.findall("Attribute")}
            self.assertEqual(names["field_along_T"], "Grid")
            if grid.find("Topology").get("TopologyType") == "Hexahedron":
                self.assertEqual(names["material_id"], "Cell")
                self.assertEqual(names["displacement"], "Node")
            else:
                self.assertEqual(grid.find("Topology").get("TopologyType"), "Polyvertex")
                self.assertEqual(names["magnetization"], "Node")
        return times

    def test_every_file_refers_to_existing_data_of_its_shape(self):
        for name, run in self.dirs.items():
            files = glob.glob(os.path.join(run, "*.xdmf")) + glob.glob(
                os.path.join(run, "xdmf", "*.xdmf"))
            self.assertEqual(len(files), 2 + len(glob.glob(os.path.join(run, "xdmf", "*"))))
            with h5py.File(os.path.join(run, "results.h5"), "r") as f:
                steps = list(f["steps/index"][()].astype(float))
            for path in files:
                with self.subTest(file=os.path.relpath(path, run)):
                    times = self.check_file(path)
                    if os.path.dirname(path) == run:
                        self.assertEqual(times, steps)

    def test_hysteresis_legs_are_timed_by_the_field(self):
        run = self.dirs["hysteresis"]
        with h5py.File(os.path.join(run, "results.h5"), "r") as f:
            field = f["steps/field_projection"][()]
        legs = sorted(glob.glob(os.path.join(run, "xdmf", "lattice_leg_*.xdmf")))
        self.assertEqual(len(legs), 3)
        times = [self.check_file(p) for p in legs]
        self.assertEqual(sum(times, []), list(field))
        np.testing.assert_allclose(times[1], [0.0, -0.05], atol=1e-12)
        particles = sorted(glob.glob(os.path.join(run, "xdmf", "particles_leg_*.xdmf")))
        self.assertEqual([self.check_file(p) for p in particles], times)

    def test_strain_legs_are_one_per_field_timed_by_the_strain(self):
        run = self.dirs["shear"]
        with h5py.File(os.path.join(run, "results.h5"), "r") as f:
            load = f["steps/load_value"][()]
            field_index = f["steps/field_index"][()]
        legs = sorted(glob.glob(os.path.join(run, "xdmf", "lattice_leg_*.xdmf")))
        self.assertEqual(len(legs), 2)
        for k, path in enumerate(legs):
            self.assertEqual(self.check_file(path), list(load[field_index == k]))
        self.assertEqual(self.check_file(legs[0]), [0.0, 0.02])

    def test_displacement_and_cell_material(self):
        run = self.dirs["hysteresis"]
        with h5py.File(os.path.join(run, "results.h5"), "r") as f:
            initial = f["lattice/initial_positions"][()]
            cells = f["lattice/cells"][()]
            node_id = f["lattice/particle_id"][()]
            material = f["lattice/cell_material"][()]
        with h5py.File(os.path.join(run, "positions", "step_000001.h5"), "r") as g:
            np.testing.assert_allclose(g["displacement"][()], g["positions"][()] - initial,
                                       atol=1e-20)
            self.assertGreater(np.abs(g["displacement"][()]).max(), 0.0)
            self.assertTrue(g["positions"].compression == "gzip" and g["positions"].shuffle)
        for k in (0, 1):
            voxels = np.all(node_id[cells] == k, axis=1)
            np.testing.assert_array_equal(material == k, voxels)
            self.assertGreater(voxels.sum(), 0)
        self.assertTrue(np.all((material == -1) == ~np.any(
            [np.all(node_id[cells] == k, axis=1) for k in (0, 1)], axis=0)))


if __name__ == "__main__":
    unittest.main()
