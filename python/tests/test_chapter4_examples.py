"""The Chapter 4 (3D lattice, MESS) run files of examples/chapter4/, when an mresim binary is
around (MRESIM_BIN, as in test_plots.py):

- every examples/chapter4/*.toml (the dissertation's full-size systems, hours each) is only
  validated: `mresim info --json` parses, and the node counts of Figs. 4.4 and 4.5 are the
  dissertation's (146,412 and 52,200);
- every examples/chapter4/small/*.toml (the scaled-down variants, seconds each) is run end to
  end: results, summary.csv with every step converged, and the figures.

    MRESIM_BIN=build/mresim /usr/bin/python3 -m unittest discover python/tests -p 'test_chapter4*'
"""

import csv
import glob
import json
import os
import shutil
import subprocess
import tempfile
import time
import unittest

import matplotlib

matplotlib.use("Agg")
import matplotlib.image  # noqa: E402

PYTHON_DIR = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
REPO = os.path.dirname(PYTHON_DIR)
CHAPTER4 = os.path.join(REPO, "examples", "chapter4")
SMALL = os.path.join(CHAPTER4, "small")
MESS_TYPES = ("mess_hysteresis", "mess_strain", "mess_magnetostriction", "mess_stress")

# Published node counts (claim D1, docs/validation.md#claims-d1-d13) of the files the dissertation
# states them for.
EXPECTED_NODES = {"fig4_4_": 146412, "fig4_5_": 52200}


def find_mresim():
    binary = os.environ.get("MRESIM_BIN", "")
    return binary if binary and os.access(binary, os.X_OK) else None


def knows_mess(binary):
    types = subprocess.run([binary, "types"], capture_output=True, text=True).stdout.split()
    return all(t in types for t in MESS_TYPES)


def full_size_files():
    return sorted(glob.glob(os.path.join(CHAPTER4, "*.toml")))


def small_files():
    return sorted(glob.glob(os.path.join(SMALL, "*.toml")))


def stem(path):
    return os.path.splitext(os.path.basename(path))[0]


class Chapter4FilesTest(unittest.TestCase):
    """Needs no binary: every full-size file has its small variant and the other way round."""

    def test_every_system_has_a_small_variant(self):
        # Figures of the dissertation (fig*): full size and small. Small examples of features
        # beyond the dissertation (e.g. field_gradient_pull_small) have no full-size file.
        full = {stem(p) for p in full_size_files()}
        small = {stem(p) for p in small_files() if stem(p).startswith("fig")}
        self.assertGreaterEqual(len(full), 14)
        self.assertEqual({s + "_small" for s in full}, small)


@unittest.skipUnless(find_mresim(), "set MRESIM_BIN=path/to/mresim to check the Chapter 4 examples")
class Chapter4InfoTest(unittest.TestCase):
    """`mresim info --json` on every full-size file: valid, parseable, the published sizes."""

    def setUp(self):
        self.binary = find_mresim()
        if not knows_mess(self.binary):
            self.skipTest("this mresim has no mess_* run types")

    def info(self, toml):
        result = subprocess.run([self.binary, "info", toml, "--json"], capture_output=True,
                                text=True, timeout=60)
        self.assertEqual(result.returncode, 0, result.stderr)
        return json.loads(result.stdout)

    def test_full_size_files(self):
        checked = set()
        for toml in full_size_files():
            name = stem(toml)
            with self.subTest(example=name):
                info = self.info(toml)
                nodes = info["lattice"]["nodes"]["value"]
                self.assertGreater(nodes, 20000, "full-size systems have n_d >= 5")
                self.assertGreater(info["mess"]["relaxations"]["value"], 1)
                for prefix, expected in EXPECTED_NODES.items():
                    if name.startswith(prefix):
                        self.assertEqual(nodes, expected)
                        checked.add(prefix)
        self.assertEqual(checked, set(EXPECTED_NODES), "the Fig. 4.4 and 4.5 files exist")

    def test_small_files_are_small(self):
        for toml in small_files():
            with self.subTest(example=stem(toml)):
                info = self.info(toml)
                self.assertLess(info["lattice"]["nodes"]["value"], 20000)
                self.assertLessEqual(info["mess"]["relaxations"]["value"], 40)


@unittest.skipUnless(find_mresim(), "set MRESIM_BIN=path/to/mresim to run the Chapter 4 examples")
class Chapter4SmallRunsTest(unittest.TestCase):
    """Every examples/chapter4/small/*.toml run and plotted by `mresim run` (about 2.5 minutes in
    all on one core of a busy 2-core machine, a third of it drawing the figures)."""

    def setUp(self):
        self.binary = find_mresim()
        if not knows_mess(self.binary):
            self.skipTest("this mresim has no mess_* run types")
        # MRESIM_EXAMPLE_RUNS=DIR keeps the runs in DIR (emptied first; CTest sets it to a folder
        # of the build tree), where the C++ test of the examples' header promises reads them
        # (chapter4_example_promises in CMakeLists.txt): each example then runs once per suite.
        self.keep = os.environ.get("MRESIM_EXAMPLE_RUNS")
        if self.keep:
            shutil.rmtree(self.keep, ignore_errors=True)
            os.makedirs(self.keep)
            self.tmp = self.keep
        else:
            self.tmp = tempfile.mkdtemp(prefix="mresim_chapter4_test_")

    def tearDown(self):
        if not self.keep:
            shutil.rmtree(self.tmp, ignore_errors=True)

    def assert_nontrivial_png(self, path):
        self.assertGreater(os.path.getsize(path), 15_000, path)
        image = matplotlib.image.imread(path)
        self.assertGreaterEqual(min(image.shape[:2]), 400, path)
        self.assertGreater(image[..., :3].std(), 0.02, f"{path} is nearly blank")

    def test_small_examples(self):
        files = small_files()
        self.assertTrue(files)
        for toml in files:
            name = stem(toml)
            with self.subTest(example=name):
                out = os.path.join(self.tmp, name)
                start = time.monotonic()
                # One thread: these lattices (< 12,000 nodes) gain little from a second one,
                # and OpenMP barriers on a busy machine can make two threads several times
                # slower than one.
                run = subprocess.run([self.binary, "run", toml, "--out", out, "--threads", "1"],
                                     capture_output=True, text=True, timeout=300)
                elapsed = time.monotonic() - start
                self.assertEqual(run.returncode, 0, run.stderr)
                self.assertTrue(os.path.isfile(os.path.join(out, "results.h5")))

                with open(os.path.join(out, "summary.csv"), newline="") as fh:
                    rows = list(csv.DictReader(fh))
                self.assertTrue(rows)
                unconverged = [r["step"] for r in rows if r["converged"] != "1"]
                self.assertEqual(unconverged, [], f"{name}: steps that did not converge")
                if "load_index" in rows[0] and any(r["load_index"] != "0" for r in rows):
                    self.assertTrue(os.path.isfile(os.path.join(out, "modulus.csv")))

                pngs = sorted(glob.glob(os.path.join(out, "figures", "*.png")))
                self.assertTrue(pngs, f"{name}: no figures")
                for png in pngs:
                    self.assert_nontrivial_png(png)
                print(f"\n  {name}: {elapsed:.1f} s, {len(rows)} steps, {len(pngs)} figures",
                      end="")


if __name__ == "__main__":
    unittest.main()
