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
#include "mresim/app/run_type.hpp"
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

namespace {

// The run file to continue: the checkpoint's effective run file, with the overrides record
// beside it (see read_with_overrides_record).
config::TableReader checkpointed_run_file(const fs::path& staging_dir) {
  std::string text;
  std::string name;
  {
    const io::Hdf5Reader checkpoint(staging_dir / mess_protocol::kCheckpointFile);
    text = checkpoint.string_attribute("/", "input_toml");
    name = checkpoint.string_attribute("/", "input_file");
  }
  return read_with_overrides_record(staging_dir, text, name);
}

}  // namespace

int resume_command(const ResumeOptions& options) {
  // Under `mpirun -np P` (P > 1) rank 0 resumes as a single process would and tells the others
  // its staging directory; they read the same checkpoint and compute alongside it (docs/mpi.md).
  const mess::MpiJob job = mess::mpi_job();
  // A resumed run continues its log.
  configure_output(job.rank == 0 ? options.output : OutputOptions{true, std::nullopt}, options.dir,
                   true);
  if (job.rank > 0) {
    const fs::path staging_dir = mess::broadcast_text({});
    const auto root = checkpointed_run_file(staging_dir);
    std::string run_type;
    const auto plan = app::make_plan(root, &run_type);
    refuse_unsplittable_plan(*plan, run_type);
    return participate_in_run(root, *plan, options.threads, job, staging_dir);
  }
  try {
    const fs::path checkpoint_name = mess_protocol::kCheckpointFile;
    // Locks DIR first: while a run or another resume holds it, nothing is taken over.
    const auto run_dir = io::RunDirectory::resume(options.dir, checkpoint_name);
    // A run with --set: the checkpoint holds the effective run file; the record beside it the
    // file as written and the overrides, so that the resumed results.h5 records them as a run
    // would.
    const auto root = checkpointed_run_file(run_dir->path());
    std::string run_type;
    const auto plan = app::make_plan(root, &run_type);
    if (job.size > 1) {
      refuse_unsplittable_plan(*plan, run_type);
      (void)mess::broadcast_text(run_dir->path().string());
    }
    if (!app::run_output().quiet()) {
      std::printf("mresim: resuming the run in %s\n", run_dir->path().string().c_str());
      std::fflush(stdout);
    }
    return execute_and_publish(root, *plan, run_type, *run_dir, options.threads, options.no_plot,
                               job);
  } catch (const std::exception& e) {
    end_job_on_error(e, job);  // the others may wait for the staging directory or a collective
    throw;
  }
}

}  // namespace mresim::cli
