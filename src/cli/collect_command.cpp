// `mresim collect DIR`: the tables of every point of a sweep in one table each
// (sweep/collect.hpp, docs/sweeps.md).

#include <fmt/format.h>

#include <cstdio>

#include "cli/commands.hpp"
#include "cli/exit_status.hpp"
#include "mresim/config/config_error.hpp"
#include "mresim/sweep/collect.hpp"

namespace mresim::cli {

CLI::App* add_collect_command(CLI::App& app, CollectOptions& options) {
  CLI::App* collect = app.add_subcommand(
      "collect",
      "Collect the tables of all points of a sweep into DIR/collected_*.csv and "
      "DIR/collected.h5, with each point's index, status and parameters (docs/sweeps.md)");
  collect->add_option("DIR", options.dir, "Sweep directory (made by 'mresim sweep')")->required();
  return collect;
}

int collect_command(const CollectOptions& options) {
  const sweep::CollectResult r = sweep::collect(options.dir);
  for (const auto& file : r.written) std::printf("mresim collect: wrote %s\n", file.c_str());
  std::printf(
      "mresim collect: %zu point(s) finished (%zu with invalid results), %zu failed, %zu "
      "not run yet\n",
      r.finished, r.invalid_results, r.failed, r.pending);
  return kSuccess;
}

void refuse_sweep_file(const config::TableReader& root, const std::string& file) {
  if (!root.has("sweep")) return;
  throw config::ConfigError(fmt::format(
      "{} has a [sweep] table: run its points with 'mresim sweep {} --out DIR' (one point: "
      "--index I), see docs/sweeps.md",
      file, file));
}

}  // namespace mresim::cli
