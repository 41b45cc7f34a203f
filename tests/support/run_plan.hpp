#pragma once

// Plans (app::make_plan) of run files written in a test, for the tests of a run type's reading,
// its `info` values and its refusals.

#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "mresim/app/info_report.hpp"
#include "mresim/app/run_type.hpp"
#include "mresim/config/config_error.hpp"
#include "mresim/config/table_reader.hpp"

namespace mresim::testing {

// The plan of the run file "[run] type = `run_type`" followed by `tables` (named test.toml).
inline std::unique_ptr<app::RunPlan> plan_of(const std::string& run_type,
                                             const std::string& tables) {
  return app::make_plan(config::TableReader::parse_string(
      "[run]\ntype = \"" + run_type + "\"\n" + tables, "test.toml"));
}

// That plan's `info` report as JSON.
inline nlohmann::json info_of(const std::string& run_type, const std::string& tables) {
  app::InfoReport report;
  plan_of(run_type, tables)->describe(report);
  return report.to_json();
}

// The number `key` of [section] in an `info` JSON report.
inline double info_value(const nlohmann::json& info, const std::string& section,
                         const std::string& key) {
  return info.at(section).at(key).at("value").get<double>();
}

// The message of the ConfigError that plan_of(run_type, tables) throws, or "no error".
inline std::string plan_error_of(const std::string& run_type, const std::string& tables) {
  try {
    (void)plan_of(run_type, tables);
  } catch (const config::ConfigError& e) {
    return e.what();
  }
  return "no error";
}

// The message of the ConfigError that making a plan of the whole run file `text` (named
// run.toml) throws, or "(no error)".
inline std::string run_file_error_of(const std::string& text) {
  try {
    (void)app::make_plan(config::TableReader::parse_string(text, "run.toml"));
  } catch (const config::ConfigError& e) {
    return e.what();
  }
  return "(no error)";
}

}  // namespace mresim::testing
