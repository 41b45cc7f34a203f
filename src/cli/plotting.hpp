#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace mresim::cli {

// Runs `python3 <python dir>/mresim_plot.py RUN_DIR [ARGS...]`, which writes
// RUN_DIR/figures/*.png; `script_args` (the view options of `mresim plot`) follow RUN_DIR.
// <python dir> is $MRESIM_PYTHON_DIR if set, else the source tree's python/ directory (compile
// definition MRESIM_PYTHON_DIR); the interpreter is $MRESIM_PYTHON if set, else python3 from
// PATH (falling back to /usr/bin/python3 when that one lacks matplotlib, numpy or h5py and
// MRESIM_PYTHON is unset). Returns the script's exit status (128 + signal if killed, 127 if
// python is missing).
// When python3 is missing, or the script fails and matplotlib/numpy/h5py cannot be imported,
// prints what to install. Throws std::runtime_error if the script does not exist.
int draw_figures(const std::filesystem::path& run_dir,
                 const std::vector<std::string>& script_args = {});

// The directory holding mresim_plot.py and the interpreter, as described above.
std::filesystem::path python_dir();
std::string python_interpreter();

}  // namespace mresim::cli
