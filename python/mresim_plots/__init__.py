"""Figures for mresim run directories, one module per run type."""

import matplotlib

matplotlib.use("Agg")  # figures are files: never open a display, whatever MPLBACKEND says

# pylint: disable=wrong-import-position
from . import magnetization_curve, mess, pair_ensemble, pair_hysteresis, pair_map  # noqa: E402

# run_type (results.h5 root attribute) -> function drawing DIR/figures/*.png from a Run
PLOTTERS = {
    "pair_hysteresis": pair_hysteresis.plot,
    "pair_map": pair_map.plot,
    "pair_ensemble": pair_ensemble.plot,
    "froehlich_kennelly": magnetization_curve.plot,
    "preisach": magnetization_curve.plot,
    "mess_hysteresis": mess.plot,
    "mess_magnetostriction": mess.plot,
    "mess_strain": mess.plot,
    "mess_stress": mess.plot,
}
