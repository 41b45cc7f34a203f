// `mresim plot DIR`: (re)draw the figures of a finished run.

#include <fmt/format.h>

#include "cli/commands.hpp"
#include "cli/plotting.hpp"
#include "mresim/io/run_directory.hpp"

namespace mresim::cli {

CLI::App* add_plot_command(CLI::App& app, PlotOptions& options) {
  CLI::App* plot = app.add_subcommand(
      "plot",
      "Draw DIR/figures/*.png from the results of a finished run (uses python3 + "
      "matplotlib; $MRESIM_PYTHON_DIR overrides where mresim_plot.py is found)");
  plot->add_option("DIR", options.dir, "Run directory (contains results.h5)")->required();
  return plot;
}

int plot_command(const PlotOptions& options) {
  if (!io::RunDirectory::is_run_directory(options.dir)) {
    throw io::OutputDirectoryError(
        fmt::format("'{}' is not an mresim run directory (no results.h5 in it)", options.dir));
  }
  return draw_figures(options.dir);
}

}  // namespace mresim::cli
