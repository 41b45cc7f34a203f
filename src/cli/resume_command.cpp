// `mresim resume DIR`: a run to DIR that was interrupted (killed, power cut) left its staging
// directory DIR.partial-<pid> with a checkpoint; this takes it over, rebuilds the plan from the
// run file stored in the checkpoint and lets the run type continue from there. Only run types
// that write checkpoints (the 3D runs, [output] checkpoint_every) can be resumed.

#include <filesystem>

#include "cli/commands.hpp"
#include "cli/exit_status.hpp"
#include "mresim/io/hdf5_reader.hpp"
#include "mresim/io/run_directory.hpp"
#include "mresim/mess_protocol/checkpoint.hpp"

namespace mresim::cli {

namespace fs = std::filesystem;

CLI::App* add_resume_command(CLI::App& app, ResumeOptions& options) {
  CLI::App* resume =
      app.add_subcommand("resume", "Continue an interrupted 3D run from its last checkpoint");
  resume->add_option("DIR", options.dir, "The output directory the interrupted run was writing")
      ->required();
  resume
      ->add_option("--threads,-j", options.threads,
                   "Number of threads; 0 = all cores (default: [run].threads, else all cores)")
      ->check(CLI::NonNegativeNumber);
  resume->add_flag("--no-plot", options.no_plot, "Do not draw figures/*.png after the run");
  resume->footer(
      "An interrupted run leaves DIR.partial-<pid>/ next to DIR; its checkpoint holds the run "
      "file, so the original file is not needed. 'mresim run' to the same DIR starts over and "
      "discards it.");
  return resume;
}

int resume_command(const ResumeOptions& options) {
  const fs::path checkpoint_name = mess_protocol::kCheckpointFile;
  const fs::path staging = io::RunDirectory::find_interrupted(options.dir, checkpoint_name);
  if (staging.empty()) {
    throw io::OutputDirectoryError("no interrupted run with a checkpoint for '" + options.dir +
                                   "' (looked for '" + options.dir + ".partial-<pid>/" +
                                   checkpoint_name.string() +
                                   "'); start it again with 'mresim run'");
  }
  std::string text;
  std::string name;
  {
    const io::Hdf5Reader checkpoint(staging / checkpoint_name);
    text = checkpoint.string_attribute("/", "input_toml");
    name = checkpoint.string_attribute("/", "input_file");
  }
  const auto root = config::TableReader::parse_string(text, name);
  std::string run_type;
  const auto plan = app::make_plan(root, &run_type);
  io::RunDirectory run_dir(options.dir, staging);
  std::printf("mresim: resuming the run in %s\n", staging.string().c_str());
  std::fflush(stdout);
  return execute_and_publish(root, *plan, run_type, run_dir, options.threads, options.no_plot);
}

}  // namespace mresim::cli
