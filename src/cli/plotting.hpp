#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace mresim::cli {

// Runs `python3 <python dir>/mresim_plot.py RUN_DIR [ARGS...]`, which writes
// RUN_DIR/figures/*.png; `script_args` (the view options of `mresim plot`) follow RUN_DIR.
// <python dir> is $MRESIM_PYTHON_DIR if set, else installed_python_dir() if that holds
// mresim_plot.py (an installed mresim), else the source tree's python/ directory (compile
// definition MRESIM_PYTHON_DIR, for the build tree's mresim); the interpreter is $MRESIM_PYTHON if
// set, else python3 from PATH (falling back to /usr/bin/python3 when that one lacks matplotlib,
// numpy or h5py and MRESIM_PYTHON is unset). Returns the script's exit status (128 + signal if
// killed, 127 if python is missing). When python3 is missing, or the script fails and
// matplotlib/numpy/h5py cannot be imported, prints what to install. Throws std::runtime_error if
// the script does not exist. `quiet`: the script's errors only (--quiet), not its "wrote N figures"
// line.
int draw_figures(const std::filesystem::path& run_dir,
                 const std::vector<std::string>& script_args = {}, bool quiet = false);

// The directory holding mresim_plot.py and the interpreter, as described above.
std::filesystem::path python_dir();
// <directory of the running executable>/../share/mresim/python (the install layout's,
// MRESIM_INSTALL_PYTHON_SCRIPTS_DIR), if mresim_plot.py is there; else empty.
std::filesystem::path installed_python_dir();
std::string python_interpreter();

}  // namespace mresim::cli
