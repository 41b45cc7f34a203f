// The compiled half of the Python package `mresim` (python/mresim/ holds the other half, which is
// what users import; docs/python.md).

#include <pybind11/pybind11.h>

#include <mresim/core/version.hpp>

#include "bindings.hpp"

PYBIND11_MODULE(_core, m) {
  m.doc() = "mresim's C++ library: run plans, run directories and the two-dipole models";
  m.attr("__version__") = mresim::kVersion;
  mresim::python::bind_errors(m);
  mresim::python::bind_run_plan(m);
  mresim::python::bind_pair(m);
}
