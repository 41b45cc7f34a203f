// `mresim rerun DIR --step K [--set solver.KEY=VALUE ...]`: relaxes one step of a finished 3D
// run again with other solver settings (mess/restart/rerun_plan.hpp). The new result replaces
// step K; the original is kept in results.h5's /history. The directory is replaced all at once.
// Under `mpirun -np P` the relaxations split over the processes, as `mresim run`'s do.

#include <fmt/format.h>

#include <string>
#include <vector>

#include "cli/commands.hpp"
#include "cli/finished_run.hpp"
#include "mresim/mess/restart/rerun_plan.hpp"
#include "mresim/mess/restart/restart_overrides.hpp"

namespace mresim::cli {

CLI::App* add_rerun_command(CLI::App& app, RerunOptions& options) {
  CLI::App* rerun = app.add_subcommand(
      "rerun", "Relax one step of a finished 3D run again with other solver settings");
  rerun->add_option("DIR", options.dir, "The output directory of the finished run")->required();
  rerun->add_option("--step", options.step, "The step to relax again (/steps/index)")
      ->required()
      ->check(CLI::NonNegativeNumber);
  add_set_option(*rerun, options.overrides);
  add_threads_option(*rerun, options.threads);
  add_output_options(*rerun, options.output);
  rerun->add_flag("--no-plot", options.no_plot, "Do not draw figures/*.png after the run");
  rerun->footer(
      "Only solver settings may change (solver.*). The step starts from the state before it; "
      "its new result replaces the old one, which is kept in /history of results.h5; later "
      "steps are not recomputed (docs/cli.md).");
  return rerun;
}

int rerun_command(const RerunOptions& options) {
  // Under `mpirun -np P` (P > 1, docs/mpi.md) rank 0 does what a single process does; the
  // others relax the same steps alongside it, reading the run directory, and write nothing.
  const mess::MpiJob job = mess::mpi_job();
  // The run's log continues.
  configure_output(job.rank == 0 ? options.output : OutputOptions{true, std::nullopt}, options.dir,
                   true);
  mess_protocol::check_rerun_overrides(options.overrides);
  const auto computed = finished_run_file(options.dir, {}, "rerun");
  const auto rerun = finished_run_file(options.dir, options.overrides, "rerun");
  std::vector<std::string> words = {"mresim", "rerun", options.dir, "--step",
                                    std::to_string(options.step)};
  for (const std::string& o : options.overrides) words.insert(words.end(), {"--set", o});
  const auto plan = mess_protocol::make_rerun_plan(
      computed, rerun, options.dir, static_cast<std::size_t>(options.step),
      new_history_entry("rerun", words, options.overrides));
  // The results record the run file the run was made with: the other steps are its results.
  return execute_on_finished_run(
      options.dir, computed, *plan,
      fmt::format("mresim: relaxing step {} of the run in {} again", options.step, options.dir),
      options.threads, options.no_plot);
}

}  // namespace mresim::cli
