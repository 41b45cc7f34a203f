// `mresim run FILE`: validate everything, then compute into a staging directory, commit it,
// and draw the figures.

#include <fmt/format.h>
#include <toml++/toml.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "cli/commands.hpp"
#include "cli/exit_status.hpp"
#include "cli/plotting.hpp"
#include "mresim/app/invalid_results.hpp"
#include "mresim/app/run_output.hpp"
#include "mresim/app/run_type.hpp"
#include "mresim/app/stop_signal.hpp"
#include "mresim/app/threads.hpp"
#include "mresim/config/overrides.hpp"
#include "mresim/config/table_reader.hpp"
#include "mresim/io/hdf5_file.hpp"
#include "mresim/io/metadata.hpp"
#include "mresim/io/run_directory.hpp"

namespace mresim::cli {

namespace fs = std::filesystem;

CLI::App* add_run_command(CLI::App& app, RunOptions& options) {
  CLI::App* run = app.add_subcommand("run", "Run a simulation described by a TOML run file");
  run->add_option("FILE", options.file, "Run file (TOML), see docs/run-files.md")->required();
  run->add_option("--out,-o", options.out,
                  "Output directory (default: ./<FILE without extension>). An earlier mresim "
                  "run there is replaced if it holds only the files mresim wrote; any other "
                  "existing directory is refused");
  add_threads_option(*run, options.threads);
  add_set_option(*run, options.overrides);
  add_output_options(*run, options.output);
  run->add_flag("--no-plot", options.no_plot, "Do not draw figures/*.png after the run");
  run->add_flag("--force", options.force,
                "Use --out even if it holds files mresim did not write: the old directory is "
                "renamed to DIR.replaced-<time> when the run finishes, never deleted");
  run->footer("Run types in this build:\n" + run_type_list());
  return run;
}

namespace {
int configure_run_threads(long threads_option, const app::RunSettings& settings,
                          const mess::MpiJob& job);
}  // namespace

int run_command(const RunOptions& options) {
  const fs::path out = options.out.empty() ? fs::path(options.file).stem() : fs::path(options.out);
  // Under `mpirun -np P` (P > 1, docs/mpi.md) rank 0 does what a single process does; the
  // others compute alongside it and say nothing (their errors still reach stderr).
  const mess::MpiJob job = mess::mpi_job();
  // 0. Messages: stderr unless --quiet, and the --log file, from the first line on.
  configure_output(job.rank == 0 ? options.output : OutputOptions{true, std::nullopt}, out, false);

  // 1. Parse and validate the whole run file, unknown keys included, before touching the disk.
  // --set overrides are applied to the parsed file first, so they are validated as the file is.
  const auto root = config::TableReader::parse_file(options.file, options.overrides);
  refuse_sweep_file(root, options.file);
  std::string run_type;
  const auto plan = app::make_plan(root, &run_type);
  if (job.size > 1) {
    refuse_unsplittable_plan(*plan, run_type);
    if (job.rank > 0) return participate_in_run(root, *plan, options.threads, job, {});
  }

  try {
    // 2. Claim the output directory (refused if it holds something other than an mresim run).
    io::RunDirectory run_dir(out, io::RunDirectory::Options{options.force});
    return execute_and_publish(root, *plan, run_type, run_dir, options.threads, options.no_plot,
                               job);
  } catch (const std::exception& e) {
    end_job_on_error(e, job);
    throw;
  }
}

void end_job_on_error(const std::exception& error, const mess::MpiJob& job) {
  if (job.size == 1) return;
  app::run_output().error(
      job.rank == 0 ? fmt::format("mresim: error: {}", error.what())
                    : fmt::format("mresim: error on MPI process {}: {}", job.rank, error.what()));
  mess::abort_job(kFailure);
}

namespace {

// Threads per process: the --threads option, else [run].threads; 0 means all cores, which the
// processes of an MPI job on one machine share (OpenMPI's OMPI_COMM_WORLD_LOCAL_SIZE).
int configure_run_threads(long threads_option, const app::RunSettings& settings,
                          const mess::MpiJob& job) {
  long threads = threads_option >= 0 ? threads_option : settings.threads;
  if (threads == 0 && job.size > 1) {
    long local = 1;
    if (const char* text = std::getenv("OMPI_COMM_WORLD_LOCAL_SIZE")) local = std::atol(text);
    threads = std::max(1L, app::max_threads() / std::max(1L, local));
  }
  return app::configure_threads(threads);
}

}  // namespace

int participate_in_run(const config::TableReader& root, const app::RunPlan& plan,
                       long threads_option, const mess::MpiJob& job, const fs::path& staging_dir) {
  (void)configure_run_threads(threads_option, app::read_run_settings(root), job);
  try {
    plan.participate(staging_dir);
  } catch (const std::exception& e) {
    end_job_on_error(e, job);
    throw;
  }
  return kSuccess;
}

void refuse_unsplittable_plan(const app::RunPlan& plan, const std::string& run_type) {
  if (!plan.splits_over_processes()) {
    throw std::invalid_argument(fmt::format(
        "run type '{}' cannot split a run over MPI processes; run it without mpirun (or with "
        "-np 1)",
        run_type));
  }
}

namespace {

// A stop signal ended the run: keep its checkpoint (if any) and say how to go on.
int report_interrupted(const app::Interrupted& e, io::RunDirectory& run_dir) {
  const std::string shown = run_dir.shown_path().string();
  if (e.resumable) {
    run_dir.keep_for_resume();
    app::run_output().error(fmt::format(
        "mresim: interrupted by {} {}; the checkpoint is in '{}'; continue with 'mresim resume {}'",
        app::signal_name(e.signal), e.what(), run_dir.path().string(), shown));
  } else {
    app::run_output().error(
        fmt::format("mresim: interrupted by {} {}; this run type writes no checkpoints, nothing "
                    "was written to '{}'",
                    app::signal_name(e.signal), e.what(), shown));
  }
  return 128 + e.signal;
}

}  // namespace

void add_threads_option(CLI::App& command, long& threads) {
  command
      .add_option("--threads,-j", threads,
                  "Number of threads; 0 = all cores (default: [run].threads, else all cores)")
      ->check(CLI::Validator(
          [](std::string& value) -> std::string {
            try {
              std::size_t used = 0;
              const long n = std::stol(value, &used);
              if (used == value.size() && n >= 0 && n <= app::max_threads()) return "";
            } catch (const std::exception&) {  // not a number, or out of long's range
            }
            return fmt::format("{}: {}", value, app::threads_allowed());
          },
          "INT", "threads"));
}

void add_set_option(CLI::App& command, std::vector<std::string>& overrides) {
  command
      .add_option("--set", overrides,
                  "Override one run-file value, KEY=VALUE: KEY a dotted key (field.max, "
                  "case[1].penalty.type), VALUE a TOML value (0.05, \"x\", [1, 2], true; a bare "
                  "word is a string). Repeatable; checked like the file (docs/cli.md)")
      ->expected(1)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll)
      ->type_name("KEY=VALUE")
      ->check(
          CLI::Validator([](std::string& value) { return config::override_syntax_error(value); },
                         "KEY=VALUE", "override"));
}

void write_overrides_record(const config::TableReader& root, const fs::path& dir) {
  toml::array overrides;
  for (const std::string& o : root.overrides()) overrides.push_back(o);
  toml::table record;
  record.insert_or_assign("file_toml", root.file_text());
  record.insert_or_assign("overrides", std::move(overrides));
  // Written whole, then renamed: a run killed meanwhile leaves no half record.
  const fs::path file = dir / kOverridesRecordFile;
  const fs::path temporary = fs::path(file.string() + ".tmp");
  {
    std::ofstream out(temporary, std::ios::binary);
    out << config::toml_text(record);
    if (!out.flush()) throw std::runtime_error("cannot write " + temporary.string());
  }
  fs::rename(temporary, file);
}

int execute_and_publish(const config::TableReader& root, const app::RunPlan& plan,
                        const std::string& run_type, io::RunDirectory& run_dir, long threads_option,
                        bool no_plot, const mess::MpiJob& job) {
  const app::RunSettings settings = app::read_run_settings(root);
  const fs::path& out = run_dir.shown_path();

  // 3. Compute into the staging directory; an exception removes it (RunDirectory destructor).
  const int threads = configure_run_threads(threads_option, settings, job);
  // A run whose results are written but partly invalid (non-finite, unconverged) is still
  // published, with the bad entries marked, and ends with an error (exit status 4).
  std::string invalid_results;
  if (!root.overrides().empty()) write_overrides_record(root, run_dir.path());
  {
    io::Hdf5File results(run_dir.path() / io::RunDirectory::kMarkerFile);
    io::write_run_metadata(results, root, run_type);
    results.write_string_attribute("/", "title", settings.title);
    results.write_int_attribute("/", "threads", threads);
    results.write_int_attribute("/", "mpi_processes", job.size);
    app::Progress progress(0, run_type);
    try {
      plan.execute(run_dir.path(), results, progress);
      // Run types without checkpoints finish their computation, then stop here. Those that stop
      // at their own safe points have finished it: a late signal does not discard it (below).
      if (!plan.stops_at_own_safe_points()) {
        app::throw_if_stop_requested("before the results were published");
      }
    } catch (const app::InvalidResults& e) {
      invalid_results = e.what();
    } catch (const app::Interrupted& e) {
      return report_interrupted(e, run_dir);
    }
    progress.finish();
    results.write_string_attribute("/", "invalid_results", invalid_results);
    results.close();
  }
  std::error_code ec;
  fs::remove(run_dir.path() / kOverridesRecordFile, ec);  // results.h5 holds it now

  // 4. Publish the complete directory in one step.
  run_dir.commit();
  const bool quiet = app::run_output().quiet();
  if (!quiet) {
    std::printf("mresim: results written to %s\n", out.string().c_str());
    if (!run_dir.moved_aside().empty()) {
      std::printf("mresim: the directory that was there (--force) is now %s\n",
                  run_dir.moved_aside().string().c_str());
    }
    std::fflush(stdout);
  }
  // A stop signal after the plan's last safe point: the results above are complete (publishing
  // them was quicker and safer than discarding hours of work); the figures are left out, and
  // the run still ends as a stopped one (128 + the signal).
  const int late_signal = app::stop_signal();
  if (late_signal != 0) {
    app::run_output().error(fmt::format(
        "mresim: {} came after the last step; the results are complete in '{}'{}",
        app::signal_name(late_signal), out.string(),
        no_plot ? std::string()
                : fmt::format(", the figures were not drawn (draw them with 'mresim plot {}')",
                              out.string())));
  }
  const int plot_status =
      no_plot || late_signal != 0 ? kSuccess : draw_figures(run_dir.final_path(), {}, quiet);
  if (plot_status != kSuccess) {
    app::run_output().error(
        fmt::format("mresim: error: drawing the figures failed; the results are complete in '{}' "
                    "(retry with 'mresim plot {}')",
                    out.string(), out.string()));
  }
  if (!invalid_results.empty()) {
    app::run_output().error(
        fmt::format("mresim: error: {}; the results in '{}' are kept with these entries marked "
                    "invalid",
                    invalid_results, out.string()));
    return late_signal != 0 ? 128 + late_signal : kInvalidResults;
  }
  if (late_signal != 0) return 128 + late_signal;
  return plot_status == kSuccess ? kSuccess : kPlotFailed;
}

}  // namespace mresim::cli
