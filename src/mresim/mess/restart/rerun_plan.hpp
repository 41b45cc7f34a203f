#pragma once

// `mresim rerun DIR --step K`: relaxes step K of a finished 3D run again with other solver
// settings (docs/cli.md). It starts from the state before step K (rebuilt from what the run
// kept, saved_run.hpp; where that state was not kept, the steps before K are first computed
// again with the run's own settings, which reproduces it), and the new result replaces step K
// everywhere the run keeps it: /steps, summary.csv, the analysis, positions/step_K.h5 and the
// final state. The original record of step K is kept in /history (run_history.hpp) with the
// command and the solver overrides. Later steps are not recomputed: they started from the
// original result of step K, which the history entry says.

#include <cstddef>
#include <filesystem>
#include <memory>

#include "mresim/app/run_type.hpp"
#include "mresim/config/table_reader.hpp"
#include "mresim/mess/restart/run_history.hpp"

namespace mresim::mess_protocol {

// `computed`: the finished run's run file; `rerun`: the same with the solver overrides.
// Throws config::ConfigError when `step` is not a step of the run.
std::unique_ptr<app::RunPlan> make_rerun_plan(const config::TableReader& computed,
                                              const config::TableReader& rerun,
                                              const std::filesystem::path& run_dir,
                                              std::size_t step, HistoryEntry entry);

}  // namespace mresim::mess_protocol
