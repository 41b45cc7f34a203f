// `mresim info FILE`: validate a run file and show what the run would compute with, without
// computing it.

#include <cstdio>
#include <string>

#include "cli/commands.hpp"
#include "cli/exit_status.hpp"
#include "mresim/app/run_type.hpp"
#include "mresim/config/table_reader.hpp"

namespace mresim::cli {

CLI::App* add_info_command(CLI::App& app, InfoOptions& options) {
  CLI::App* info = app.add_subcommand(
      "info", "Validate a run file and print every derived quantity, without running it");
  info->add_option("FILE", options.file, "Run file (TOML)")->required();
  info->add_flag("--json", options.json, "Print JSON: {section: {key: {value, unit, note}}}");
  add_set_option(*info, options.overrides);
  return info;
}

int info_command(const InfoOptions& options) {
  const auto root = config::TableReader::parse_file(options.file, options.overrides);
  refuse_sweep_file(root, options.file);
  std::string run_type;
  const auto plan = app::make_plan(root, &run_type);
  const app::RunSettings settings = app::read_run_settings(root);

  app::InfoReport report;
  report.add_text("run", "file", root.source_name());
  if (!root.overrides().empty()) {
    std::string applied;
    for (const std::string& o : root.overrides()) applied += (applied.empty() ? "" : "; ") + o;
    report.add_text("run", "overrides", applied, "--set, applied in this order");
  }
  report.add_text("run", "type", run_type);
  if (!settings.title.empty()) report.add_text("run", "title", settings.title);
  report.add_integer("run", "threads", settings.threads, "", "0 = all cores");
  plan->describe(report);

  const std::string text = options.json ? report.to_json().dump(2) + "\n" : report.to_text();
  std::fputs(text.c_str(), stdout);
  return kSuccess;
}

}  // namespace mresim::cli
