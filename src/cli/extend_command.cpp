// `mresim extend DIR --set KEY=VALUE ...`: continues a finished 3D run with a longer field or
// load sequence (mess/restart/extend_plan.hpp). The extended run file is the run's own with the
// new overrides applied after its own ones; it is validated like `mresim run`'s, then the keys
// and the planned steps are checked to only lengthen the protocol, before anything is written.
// The directory is replaced all at once, as by `mresim run`; an interrupted extend leaves the
// original run as it was and a staging directory that `mresim resume DIR` continues.
// Under `mpirun -np P` the new steps' relaxations split over the processes, as `mresim run`'s do.

#include <string>
#include <vector>

#include "cli/commands.hpp"
#include "cli/finished_run.hpp"
#include "mresim/mess/restart/extend_plan.hpp"
#include "mresim/mess/restart/restart_overrides.hpp"

namespace mresim::cli {

CLI::App* add_extend_command(CLI::App& app, ExtendOptions& options) {
  CLI::App* extend = app.add_subcommand(
      "extend", "Continue a finished 3D run with more field or load values (--set field.max=...)");
  extend->add_option("DIR", options.dir, "The output directory of the finished run")->required();
  add_set_option(*extend, options.overrides);
  add_threads_option(*extend, options.threads);
  add_output_options(*extend, options.output);
  extend->add_flag("--no-plot", options.no_plot, "Do not draw figures/*.png after the run");
  extend->footer(
      "Only keys that lengthen the protocol are accepted: field.max, field.steps, "
      "field.magnitudes, field.values, field.sequence, and max, steps, values of [strain] and "
      "[stress]. The computed steps are kept; only the new ones are computed (docs/cli.md).");
  return extend;
}

int extend_command(const ExtendOptions& options) {
  // Under `mpirun -np P` (P > 1, docs/mpi.md) rank 0 does what a single process does; the
  // others wait for its prepared staging directory and compute the new steps alongside it.
  const mess::MpiJob job = mess::mpi_job();
  // The run's log continues.
  configure_output(job.rank == 0 ? options.output : OutputOptions{true, std::nullopt}, options.dir,
                   true);
  mess_protocol::check_extend_overrides(options.overrides);
  const auto computed = finished_run_file(options.dir, {}, "extend");
  const auto extended = finished_run_file(options.dir, options.overrides, "extend");
  std::vector<std::string> words = {"mresim", "extend", options.dir};
  for (const std::string& o : options.overrides) words.insert(words.end(), {"--set", o});
  // The plan validates the extended file as `mresim run` would, then checks the steps.
  const auto plan = mess_protocol::make_extend_plan(
      computed, extended, options.dir, new_history_entry("extend", words, options.overrides));
  return execute_on_finished_run(options.dir, extended, *plan,
                                 "mresim: extending the run in " + options.dir, options.threads,
                                 options.no_plot);
}

}  // namespace mresim::cli
