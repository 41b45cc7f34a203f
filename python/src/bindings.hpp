#pragma once

// The parts of the extension module mresim._core, one binding function per file.

#include <pybind11/pybind11.h>

namespace mresim::python {

// ConfigError, OutputDirectoryError: Python exceptions carrying the command line's messages.
void bind_errors(pybind11::module_& m);
// RunPlan: a validated run file; info (describe) and execution into a run directory.
void bind_run_plan(pybind11::module_& m);
// PairModel and the eq. 2.10 / Puljiz formulas: the two-dipole models at single states.
void bind_pair(pybind11::module_& m);

}  // namespace mresim::python
