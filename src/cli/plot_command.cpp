// `mresim plot DIR`: (re)draw the figures of a finished run.

#include <fmt/format.h>

#include "cli/commands.hpp"
#include "cli/plotting.hpp"
#include "mresim/io/run_directory.hpp"
#include "mresim/sweep/sweep_directory.hpp"

namespace mresim::cli {

CLI::App* add_plot_command(CLI::App& app, PlotOptions& options) {
  CLI::App* plot = app.add_subcommand(
      "plot",
      "Draw DIR/figures/*.png from the results of a finished run (uses python3 + "
      "matplotlib; $MRESIM_PYTHON_DIR overrides where mresim_plot.py is found)");
  plot->add_option("DIR", options.dir, "Run directory (contains results.h5)")->required();
  // One value per occurrence (repeat the option, or give a comma list): a vector option would
  // otherwise swallow DIR when it follows.
  const auto repeatable = [&](const char* name, std::vector<std::string>& values,
                              const char* help) {
    plot->add_option(name, values, help)
        ->expected(1)
        ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll)
        ->type_name("TEXT");
  };
  repeatable("--step", options.steps,
             "3D runs: steps of the cut figures: N, A-B, last, all; comma list or repeated "
             "(default: last)");
  repeatable("--plane", options.planes,
             "3D runs: cuts: x|y|z (through --particle's centre), y@K (through particle K), "
             "y=4.5e-6 (m), y=4.5um, y=mid; comma list or repeated (default: y)");
  plot->add_option("--particle", options.particle,
                   "3D runs: particle of bare-axis planes and of particle_voxels.png (default 0)")
      ->type_name("K");
  repeatable("--field-map", options.field_maps,
             "3D runs: maps of strain_map_*.png, e.g. u, uz, eps_xz, eps_eq, green_eq, "
             "sigma_xz, sigma_vm, pressure; comma list or repeated (default: "
             "u,eps_eq,green_eq,sigma_vm)");
  plot->add_flag("--animate", options.animate,
                 "3D runs: also write figures/animation.mp4 (ffmpeg) or animation.gif");
  plot->footer("Plotting scripts: " + python_dir().string());
  return plot;
}

std::vector<std::string> plot_script_arguments(const PlotOptions& options) {
  std::vector<std::string> args;
  const auto add = [&](const char* name, const std::string& value) {
    args.emplace_back(name);
    args.push_back(value);
  };
  for (const auto& s : options.steps) add("--step", s);
  for (const auto& p : options.planes) add("--plane", p);
  if (!options.particle.empty()) add("--particle", options.particle);
  for (const auto& m : options.field_maps) add("--field-map", m);
  if (options.animate) args.emplace_back("--animate");
  return args;
}

int plot_command(const PlotOptions& options) {
  // A sweep directory: the cross-run figures from its collected tables (docs/sweeps.md).
  if (sweep::is_sweep_directory(options.dir) && !io::RunDirectory::is_run_directory(options.dir)) {
    return draw_figures(options.dir, plot_script_arguments(options));
  }
  if (!io::RunDirectory::is_run_directory(options.dir)) {
    throw io::OutputDirectoryError(
        fmt::format("'{}' is not an mresim run directory (no results.h5 in it)", options.dir));
  }
  return draw_figures(options.dir, plot_script_arguments(options));
}

}  // namespace mresim::cli
