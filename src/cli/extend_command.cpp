// `mresim extend DIR --set KEY=VALUE ...`: continues a finished 3D run with a longer field or
// load sequence (mess/restart/extend_plan.hpp). The extended run file is the run's own with the
// new overrides applied after its own ones; it is validated like `mresim run`'s, then the keys
// and the planned steps are checked to only lengthen the protocol, before anything is written.
// The directory is replaced all at once, as by `mresim run`; an interrupted extend leaves the
// original run as it was and a staging directory that `mresim resume DIR` continues.

#include <cstdio>
#include <string>
#include <vector>

#include "cli/commands.hpp"
#include "cli/finished_run.hpp"
#include "mresim/app/run_type.hpp"
#include "mresim/io/run_directory.hpp"
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
  refuse_mpi_job("extend");
  configure_output(options.output, options.dir, true);  // the run's log continues
  mess_protocol::check_extend_overrides(options.overrides);
  const auto computed = finished_run_file(options.dir, {}, "extend");
  const auto extended = finished_run_file(options.dir, options.overrides, "extend");
  std::vector<std::string> words = {"mresim", "extend", options.dir};
  for (const std::string& o : options.overrides) words.insert(words.end(), {"--set", o});
  // The plan validates the extended file as `mresim run` would, then checks the steps.
  const auto plan = mess_protocol::make_extend_plan(
      computed, extended, options.dir, new_history_entry("extend", words, options.overrides));

  io::RunDirectory run_dir(options.dir);
  std::printf("mresim: extending the run in %s\n", options.dir.c_str());
  std::fflush(stdout);
  return execute_and_publish(extended, *plan, app::read_run_settings(extended).type, run_dir,
                             options.threads, options.no_plot);
}

}  // namespace mresim::cli
