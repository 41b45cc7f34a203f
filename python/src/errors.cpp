// Exceptions of the library as Python exceptions, with the messages the command line prints
// after "mresim: error: " (src/cli/main.cpp), so that a script and a shell user read the same.

#include <pybind11/pybind11.h>

#include "bindings.hpp"
#include "mresim/config/config_error.hpp"
#include "mresim/io/run_directory.hpp"

namespace py = pybind11;

namespace mresim::python {

void bind_errors(py::module_& m) {
  // Bad run-file input is a bad value: catching ValueError catches it (exit status 2 on the CLI).
  auto& config_error =
      py::register_exception<config::ConfigError>(m, "ConfigError", PyExc_ValueError);
  // A refused output directory (not an mresim run, locked by another run): an OSError.
  auto& directory_error =
      py::register_exception<io::OutputDirectoryError>(m, "OutputDirectoryError", PyExc_OSError);
  // Shown as users import them (mresim.ConfigError), not as mresim._core.ConfigError.
  config_error.attr("__module__") = "mresim";
  directory_error.attr("__module__") = "mresim";
}

}  // namespace mresim::python
