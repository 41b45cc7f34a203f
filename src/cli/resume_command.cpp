// `mresim resume DIR`: a run to DIR that was interrupted (killed, power cut) left its staging
// directory DIR.partial-<pid> with a checkpoint; this takes it over, rebuilds the plan from the
// run file stored in the checkpoint and lets the run type continue from there. Only run types
// that write checkpoints (the 3D runs, [output] checkpoint_every) can be resumed.

#include <toml++/toml.h>

#include <cstdio>
#include <exception>
#include <filesystem>
#include <string>
#include <vector>

#include "cli/commands.hpp"
#include "cli/exit_status.hpp"
#include "mresim/app/run_output.hpp"
#include "mresim/io/hdf5_reader.hpp"
#include "mresim/io/run_directory.hpp"
#include "mresim/mess/outputs/checkpoint.hpp"

namespace mresim::cli {

namespace fs = std::filesystem;

CLI::App* add_resume_command(CLI::App& app, ResumeOptions& options) {
  CLI::App* resume =
      app.add_subcommand("resume", "Continue an interrupted 3D run from its last checkpoint");
  resume->add_option("DIR", options.dir, "The output directory the interrupted run was writing")
      ->required();
  add_threads_option(*resume, options.threads);
  add_output_options(*resume, options.output);
  resume->add_flag("--no-plot", options.no_plot, "Do not draw figures/*.png after the run");
  resume->footer(
      "An interrupted run (killed, or stopped by SIGINT/SIGTERM) leaves DIR.partial-<pid>/ next "
      "to DIR; its checkpoint holds the run file, so the original file is not needed. 'mresim "
      "run' to the same DIR starts over and discards it.");
  return resume;
}

config::TableReader read_with_overrides_record(const fs::path& dir,
                                               const std::string& effective_text,
                                               const std::string& name) {
  const fs::path file = dir / kOverridesRecordFile;
  std::error_code ec;
  if (fs::exists(file, ec)) {
    try {
      const toml::table record = toml::parse_file(file.string());
      std::vector<std::string> overrides;
      if (const auto* list = record["overrides"].as_array()) {
        for (const auto& o : *list) overrides.push_back(o.value_or(std::string()));
      }
      const auto file_text = record["file_toml"].value<std::string>();
      if (file_text && !overrides.empty()) {
        auto root = config::TableReader::parse_string(*file_text, name, overrides);
        if (root.source_text() == effective_text) return root;
      }
    } catch (const std::exception&) {  // unreadable: resume without it, say so below
    }
    app::warn(file.string() +
              " does not match the checkpoint; the results will record the effective run file "
              "only, without input_overrides and input_file_toml");
  }
  return config::TableReader::parse_string(effective_text, name);
}

int resume_command(const ResumeOptions& options) {
  refuse_mpi_job("resume");
  configure_output(options.output, options.dir, true);  // a resumed run continues its log
  const fs::path checkpoint_name = mess_protocol::kCheckpointFile;
  // Locks DIR first: while a run or another resume holds it, nothing is taken over.
  const auto run_dir = io::RunDirectory::resume(options.dir, checkpoint_name);
  std::string text;
  std::string name;
  {
    const io::Hdf5Reader checkpoint(run_dir->path() / checkpoint_name);
    text = checkpoint.string_attribute("/", "input_toml");
    name = checkpoint.string_attribute("/", "input_file");
  }
  // A run with --set: the checkpoint holds the effective run file; the record beside it the file
  // as written and the overrides, so that the resumed results.h5 records them as a run would.
  const auto root = read_with_overrides_record(run_dir->path(), text, name);
  std::string run_type;
  const auto plan = app::make_plan(root, &run_type);
  if (!app::run_output().quiet()) {
    std::printf("mresim: resuming the run in %s\n", run_dir->path().string().c_str());
    std::fflush(stdout);
  }
  return execute_and_publish(root, *plan, run_type, *run_dir, options.threads, options.no_plot);
}

}  // namespace mresim::cli
