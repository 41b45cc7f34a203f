// `mresim types`: the run types this build knows, i.e. the accepted values of [run].type.

#include <fmt/format.h>

#include <algorithm>
#include <cstdio>

#include "cli/commands.hpp"
#include "cli/exit_status.hpp"
#include "mresim/app/run_type.hpp"

namespace mresim::cli {

std::string run_type_list() {
  std::size_t width = 0;
  for (const auto& t : app::run_types()) width = std::max(width, t.name.size());
  std::string text;
  for (const auto& t : app::run_types())
    text += fmt::format("  {:<{}}  {}\n", t.name, width, t.summary);
  return text.empty() ? "  (none)\n" : text;
}

CLI::App* add_types_command(CLI::App& app) {
  return app.add_subcommand("types", "List the run types ([run].type values) of this build");
}

int types_command() {
  std::fputs(run_type_list().c_str(), stdout);
  return kSuccess;
}

}  // namespace mresim::cli
