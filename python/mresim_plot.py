#!/usr/bin/env python3
"""Draw DIR/figures/*.png for a finished mresim run: `python3 mresim_plot.py DIR`.

Reads the root attribute run_type of DIR/results.h5 and hands the run to the module of
mresim_plots for that type. Exit status 0 on success; 1 with a one-line message on stderr
when the directory cannot be plotted; 2 on a wrong command line.
"""

import os
import sys

PROG = "mresim_plot"


def main(argv):
    if len(argv) != 2 or argv[1] in ("-h", "--help"):
        print(f"usage: {PROG}.py RUN_DIR", file=sys.stderr)
        return 2
    try:
        from mresim_plots import PLOTTERS
        from mresim_plots.common import PlotError, Run
    except ImportError as e:  # matplotlib, numpy or h5py missing
        print(f"{PROG}: error: {e}", file=sys.stderr)
        return 1
    directory = argv[1]
    try:
        if not os.path.isdir(directory):
            raise PlotError(f"'{directory}' is not a directory")
        run = Run(directory)
        if not run.run_type:
            raise PlotError(f"{run.h5_path} has no root attribute run_type")
        plotter = PLOTTERS.get(run.run_type)
        if plotter is None:
            known = ", ".join(sorted(PLOTTERS))
            raise PlotError(f"no figures for run type '{run.run_type}' (known: {known})")
        plotter(run)
    except PlotError as e:
        print(f"{PROG}: error: {e}", file=sys.stderr)
        return 1
    except (OSError, KeyError, ValueError, IndexError) as e:
        print(f"{PROG}: error: cannot plot '{directory}': {type(e).__name__}: {e}",
              file=sys.stderr)
        return 1
    names = ", ".join(os.path.basename(p) for p in run.written)
    print(f"{PROG}: wrote {len(run.written)} figure(s) to {run.figures_dir}: {names}")
    return 0


if __name__ == "__main__":
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    sys.exit(main(sys.argv))
