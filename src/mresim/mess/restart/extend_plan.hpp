#pragma once

// `mresim extend DIR`: the plan that continues a finished 3D run with a longer field or load
// sequence (docs/cli.md). It is the run type's own plan for the extended run file, started in a
// staging directory prepared like an interrupted run's:
//  - checkpoint.h5 holds the state after the last computed step the extended protocol shares
//    (or the latest earlier one whose state was kept), with the records of the steps before;
//  - positions/ holds the kept per-step positions of those steps;
//  - .mresim-history.h5 holds the run's history plus this extend's entry,
// so the run type computes only the new steps, the results continue as if the run had been
// made with the extended file, and an interrupted extend is resumed by `mresim resume DIR`.

#include <filesystem>
#include <memory>
#include <string>

#include "mresim/app/run_type.hpp"
#include "mresim/config/table_reader.hpp"
#include "mresim/mess/restart/run_history.hpp"

namespace mresim::mess_protocol {

// `computed`: the finished run's run file (as it ran); `extended`: the same with the extend's
// --set overrides; `entry`: this command's history entry (kind, time, command line, overrides,
// version), completed by the plan. Throws config::ConfigError if the extended protocol does not
// keep the computed steps or adds none (before anything is written).
std::unique_ptr<app::RunPlan> make_extend_plan(const config::TableReader& computed,
                                               const config::TableReader& extended,
                                               const std::filesystem::path& run_dir,
                                               HistoryEntry entry);

}  // namespace mresim::mess_protocol
