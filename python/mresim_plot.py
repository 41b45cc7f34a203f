#!/usr/bin/env python3
"""Draw DIR/figures/*.png for a finished mresim run, or the cross-run figures of a sweep
directory (sweep.json and collected.h5, mresim_plots/sweep.py):

    python3 mresim_plot.py DIR [--step S]... [--plane P]... [--particle K] [--field-map C]...
                               [--animate]

Reads the root attribute run_type of DIR/results.h5 and hands the run to the module of
mresim_plots for that type. The options choose the view figures of the 3D run types
(mresim_plots/view_options.py; docs/cli.md#mresim-plot-dir). Exit status 0 on success; 1 with
a one-line message on stderr when the directory cannot be plotted; 2 on a wrong command line,
an option value that is wrong or that the run cannot honour (one line naming the option, the
value and what is allowed).
"""

import argparse
import os
import sys

PROG = "mresim_plot"


VIEW_RUN_TYPES = ("mess_hysteresis", "mess_magnetostriction", "mess_strain", "mess_stress")


class _Parser(argparse.ArgumentParser):
    """Command-line errors as one line and exit status 2."""

    def error(self, message):
        print(f"{PROG}: error: {message}", file=sys.stderr)
        sys.exit(2)


def parse_args(argv):
    parser = _Parser(prog=f"{PROG}.py", description="Draw DIR/figures/*.png of an mresim run.")
    parser.add_argument("directory", metavar="RUN_DIR")
    parser.add_argument("--step", action="append", default=[], metavar="S",
                        help="steps of the view figures: N, A-B, last, all (comma list)")
    parser.add_argument("--plane", action="append", default=[], metavar="P",
                        help="cuts: x|y|z (through --particle), y@K, y=4.5e-6, y=4.5um, y=mid")
    parser.add_argument("--particle", default=None, metavar="K",
                        help="particle of bare-axis planes and particle_voxels.png (default 0)")
    parser.add_argument("--field-map", action="append", default=[], metavar="C",
                        dest="field_map", help="maps of strain_map_*.png (comma list)")
    parser.add_argument("--animate", action="store_true",
                        help="also write animation.mp4 (ffmpeg) or animation.gif")
    return parser.parse_args(argv[1:])


def main(argv):
    if len(argv) < 2:
        print(f"usage: {PROG}.py RUN_DIR [--step S] [--plane P] [--particle K] "
              "[--field-map C] [--animate]", file=sys.stderr)
        return 2
    args = parse_args(argv)
    try:
        from mresim_plots import PLOTTERS
        from mresim_plots.common import PlotError, Run
        from mresim_plots.view_options import OptionError, parse
    except ImportError as e:  # matplotlib, numpy or h5py missing
        print(f"{PROG}: error: {e}", file=sys.stderr)
        return 1
    try:
        options = parse(args.step, args.plane, args.particle, args.field_map, args.animate)
    except OptionError as e:
        print(f"{PROG}: error: {e}", file=sys.stderr)
        return 2
    directory = args.directory
    try:
        if not os.path.isdir(directory):
            raise PlotError(f"'{directory}' is not a directory")
        if _is_sweep_directory(directory):
            return _plot_sweep(directory, args)
        run = Run(directory, options)
        if not run.run_type:
            raise PlotError(f"{run.h5_path} has no root attribute run_type")
        plotter = PLOTTERS.get(run.run_type)
        if plotter is None:
            known = ", ".join(sorted(PLOTTERS))
            raise PlotError(f"no figures for run type '{run.run_type}' (known: {known})")
        given = [f"--{name.replace('_', '-')}" for name in ("step", "plane", "particle",
                                                              "field_map", "animate")
                 if getattr(args, name)]
        if given and run.run_type not in VIEW_RUN_TYPES:
            raise OptionError(f"{', '.join(given)}: view options apply to the 3D run types "
                              f"({', '.join(VIEW_RUN_TYPES)}), not to {run.run_type}")
        plotter(run)
        if given and not hasattr(run, "views"):  # mess_views.plot_views sets it
            raise PlotError(f"{', '.join(given)}: the {run.run_type} figures drew no view "
                            "figures, so the options were not used")
    except OptionError as e:
        print(f"{PROG}: error: {e}", file=sys.stderr)
        return 2
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


def _is_sweep_directory(directory):
    """A directory of `mresim sweep` (sweep.json, no results.h5 of its own)."""
    return (os.path.isfile(os.path.join(directory, "sweep.json"))
            and not os.path.isfile(os.path.join(directory, "results.h5")))


def _plot_sweep(directory, args):
    """The cross-run figures of a sweep (mresim_plots/sweep.py); no view options."""
    from mresim_plots import sweep
    from mresim_plots.common import PlotError
    given = [f"--{name.replace('_', '-')}" for name in ("step", "plane", "particle",
                                                          "field_map", "animate")
             if getattr(args, name)]
    if given:
        print(f"{PROG}: error: {', '.join(given)}: view options apply to run directories, not "
              f"to the sweep directory '{directory}' (plot a point: mresim plot "
              f"{directory}/point-0000 ...)", file=sys.stderr)
        return 2
    try:
        figures = sweep.Sweep(directory)
        sweep.plot(figures)
    except PlotError as e:
        print(f"{PROG}: error: {e}", file=sys.stderr)
        return 1
    except (OSError, KeyError, ValueError, IndexError) as e:
        print(f"{PROG}: error: cannot plot '{directory}': {type(e).__name__}: {e}",
              file=sys.stderr)
        return 1
    names = ", ".join(os.path.basename(p) for p in figures.written)
    print(f"{PROG}: wrote {len(figures.written)} figure(s) to {figures.figures_dir}: {names}")
    return 0


if __name__ == "__main__":
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    sys.exit(main(sys.argv))
