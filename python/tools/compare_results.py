#!/usr/bin/python3
"""Compare two sets of run directories dataset by dataset.

    python3 python/tools/compare_results.py BEFORE AFTER

BEFORE and AFTER each hold run directories of the same names (for example every
examples/chapter4/small/*.toml run with `mresim run FILE --out BEFORE/<name> --threads 1` by two
builds). Every dataset of BEFORE/<name>/results.h5 is compared with the same dataset in AFTER:
floating-point ones bitwise (NaN equal to NaN), and the largest difference relative to the
dataset's largest magnitude is printed when they differ; others must be equal. Wall-clock times
and memory (datasets ending in wall_time or peak_resident_memory) are skipped. Exit status 1 if anything differs or is missing.
A refactoring that keeps the order of floating-point operations must print 0 differing datasets.
"""
import os
import sys

import h5py
import numpy as np


def compare_file(name, before, after, tally, problems):
    with h5py.File(before) as a, h5py.File(after) as b:
        def visit(path, obj):
            if not isinstance(obj, h5py.Dataset) or path.endswith(("wall_time",
                                                                    "peak_resident_memory")):
                return
            if path not in b:
                problems.append(f"{name}:{path} missing in {after}")
                return
            x, y = obj[()], b[path][()]
            if isinstance(x, np.ndarray) and x.dtype.kind == "f":
                if x.shape != y.shape:
                    problems.append(f"{name}:{path} shape {x.shape} vs {y.shape}")
                elif np.array_equal(x, y, equal_nan=True):
                    tally["equal"] += 1
                else:
                    scale = np.nanmax(np.abs(x)) if x.size else 1.0
                    diff = np.nanmax(np.abs(x - y)) / (scale if scale > 0 else 1.0)
                    tally["worst"] = max(tally["worst"], diff)
                    problems.append(f"{name}:{path} differs, relative {diff:.3g}")
            elif np.array_equal(np.asarray(x), np.asarray(y)):
                tally["equal"] += 1
            else:
                problems.append(f"{name}:{path} differs")
        a.visititems(visit)


def main(argv):
    if len(argv) != 3:
        print(__doc__, file=sys.stderr)
        return 2
    before_root, after_root = argv[1], argv[2]
    tally = {"equal": 0, "worst": 0.0}
    problems = []
    for name in sorted(os.listdir(before_root)):
        before = os.path.join(before_root, name, "results.h5")
        if not os.path.isfile(before):
            continue
        after = os.path.join(after_root, name, "results.h5")
        if not os.path.isfile(after):
            problems.append(f"{name}: no results.h5 in {after_root}")
            continue
        compare_file(name, before, after, tally, problems)
    print(f"equal datasets: {tally['equal']}, differing or missing: {len(problems)}, "
          f"largest relative difference: {tally['worst']:.3g}")
    for p in problems:
        print("  " + p)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
