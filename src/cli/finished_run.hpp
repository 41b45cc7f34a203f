#pragma once

// A finished 3D run in an output directory, as `mresim extend` and `mresim rerun` find it: its
// run file is rebuilt from results.h5 (the file as written and the --set overrides it ran
// with, or the effective run file), so the original file is not needed.

#include <filesystem>
#include <string>
#include <vector>

#include "mresim/app/run_type.hpp"
#include "mresim/config/table_reader.hpp"
#include "mresim/mess/restart/run_history.hpp"

namespace mresim::cli {

// The run file `dir` was made with, with `more` overrides applied after the run's own. Throws
// io::OutputDirectoryError (exit status 2) when `dir` holds no finished mresim run or one of a
// run type other than the 3D ones (`command` names the command in the message).
config::TableReader finished_run_file(const std::filesystem::path& dir,
                                      const std::vector<std::string>& more,
                                      const std::string& command);

// Runs `plan` (an extend's or a rerun's) on the finished run in `dir` and publishes the
// directory as `mresim run` does, `root` being the run file the results record. Under `mpirun
// -np P` (P > 1) rank 0 does this; the other processes compute alongside it through
// plan.participate() and write nothing; an error on any process ends the job (the others may
// wait in a collective call). `announcement`: rank 0's first line on stdout.
int execute_on_finished_run(const std::filesystem::path& dir, const config::TableReader& root,
                            const app::RunPlan& plan, const std::string& announcement, long threads,
                            bool no_plot);

// A history entry of `kind` for this moment and this program, with its command line and overrides.
mess_protocol::HistoryEntry new_history_entry(const std::string& kind,
                                              const std::vector<std::string>& command_words,
                                              const std::vector<std::string>& overrides);

}  // namespace mresim::cli
