#pragma once

#include <CLI/CLI.hpp>
#include <exception>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "mresim/app/run_type.hpp"
#include "mresim/config/table_reader.hpp"
#include "mresim/io/run_directory.hpp"
#include "mresim/mess/distributed/mpi_job.hpp"

namespace mresim::cli {

// Each command registers its options on the CLI11 app and runs from the parsed values.
// Errors propagate as exceptions; main() turns them into messages and exit statuses.

// --quiet and --log FILE of run and resume (run_log.cpp; docs/cli.md#progress-and-logs).
struct OutputOptions {
  bool quiet = false;
  std::optional<std::string> log;
};
void add_output_options(CLI::App& command, OutputOptions& options);
// Points app::run_output() where `options` say, opening the log (truncated, or appended to when
// `append`: a resumed run continues its log). Throws io::OutputDirectoryError (exit status 2)
// for a log inside `out_dir` or its staging directory, or one that cannot be opened for writing.
void configure_output(const OutputOptions& options, const std::filesystem::path& out_dir,
                      bool append);

struct RunOptions {
  std::string file;
  std::string out;    // empty: ./<run file stem>
  long threads = -1;  // -1: take [run].threads
  bool no_plot = false;
  bool force = false;  // move an unrecognised existing --out aside instead of refusing
  std::vector<std::string> overrides;  // --set KEY=VALUE, repeatable, in order
  OutputOptions output;
};
CLI::App* add_run_command(CLI::App& app, RunOptions& options);
int run_command(const RunOptions& options);

// Shared by run and resume: executes the plan into run_dir's staging directory (results.h5
// with the run's metadata), commits it and draws the figures. Returns the exit status; a stop
// signal (stop_signal.hpp) ends it with 128 + the signal after keeping any checkpoint (or,
// for a plan that stops at its own safe points and had finished, after publishing the
// complete results without figures: RunPlan::stops_at_own_safe_points).
// `job`: the MPI job of `mpirun -np P mresim run` (rank 0 calls this; docs/mpi.md).
int execute_and_publish(const config::TableReader& root, const app::RunPlan& plan,
                        const std::string& run_type, io::RunDirectory& run_dir, long threads_option,
                        bool no_plot, const mess::MpiJob& job = {});

// A process other than rank 0 of `mpirun -np P mresim run/resume`: the plan's computation
// alongside rank 0 (RunPlan::participate), nothing written; `staging_dir`: rank 0's, when it
// resumes. An error here ends the whole job (rank 0 may be waiting for it).
int participate_in_run(const config::TableReader& root, const app::RunPlan& plan,
                       long threads_option, const mess::MpiJob& job,
                       const std::filesystem::path& staging_dir);
// Under mpirun with P > 1, for an error on this process: prints it and ends every process of
// the job (MPI_Abort), since the others may be waiting for this one in a collective call;
// returns at once for a single process (the caller rethrows).
void end_job_on_error(const std::exception& error, const mess::MpiJob& job);
// Under mpirun with P > 1: throws std::invalid_argument unless the plan splits over processes.
void refuse_unsplittable_plan(const app::RunPlan& plan, const std::string& run_type);

// A run with --set overrides keeps them and the run file as written in this file of its staging
// directory while it computes, so that `mresim resume` (whose checkpoint holds only the
// effective run file) records them in results.h5 too; removed before the results are published.
inline constexpr const char* kOverridesRecordFile = ".mresim-overrides.toml";
void write_overrides_record(const config::TableReader& root, const std::filesystem::path& dir);
// The run file of `effective_text` as it was made: the recorded file with the recorded overrides
// applied, when `dir` holds a record whose result is exactly `effective_text`; else
// `effective_text` as a plain run file (a run without overrides).
config::TableReader read_with_overrides_record(const std::filesystem::path& dir,
                                               const std::string& effective_text,
                                               const std::string& name);

// `mresim resume DIR`: continues an interrupted run from its last checkpoint.
struct ResumeOptions {
  std::string dir;
  long threads = -1;
  bool no_plot = false;
  OutputOptions output;
};
CLI::App* add_resume_command(CLI::App& app, ResumeOptions& options);
int resume_command(const ResumeOptions& options);

// `mresim extend DIR --set ...` and `mresim rerun DIR --step K`: continue a finished 3D run
// (extend_command.cpp, rerun_command.cpp; docs/cli.md).
struct ExtendOptions {
  std::string dir;
  std::vector<std::string> overrides;  // --set KEY=VALUE: only keys that lengthen the protocol
  long threads = -1;
  bool no_plot = false;
  OutputOptions output;
};
CLI::App* add_extend_command(CLI::App& app, ExtendOptions& options);
int extend_command(const ExtendOptions& options);

struct RerunOptions {
  std::string dir;
  long step = -1;
  std::vector<std::string> overrides;  // --set solver.KEY=VALUE
  long threads = -1;
  bool no_plot = false;
  OutputOptions output;
};
CLI::App* add_rerun_command(CLI::App& app, RerunOptions& options);
int rerun_command(const RerunOptions& options);

struct InfoOptions {
  std::string file;
  bool json = false;
  std::vector<std::string> overrides;  // --set KEY=VALUE, as for run
};
CLI::App* add_info_command(CLI::App& app, InfoOptions& options);
int info_command(const InfoOptions& options);

// `mresim plot DIR`: the view options are passed on to mresim_plot.py as given, which checks
// them (python/mresim_plots/view_options.py; docs/cli.md).
struct PlotOptions {
  std::string dir;
  std::vector<std::string> steps;       // --step, repeatable
  std::vector<std::string> planes;      // --plane, repeatable
  std::string particle;                 // --particle, empty: not given
  std::vector<std::string> field_maps;  // --field-map, repeatable
  bool animate = false;
};

// The arguments after DIR for mresim_plot.py: "--step S" per value and so on.
std::vector<std::string> plot_script_arguments(const PlotOptions& options);
CLI::App* add_plot_command(CLI::App& app, PlotOptions& options);
int plot_command(const PlotOptions& options);

// `mresim sweep FILE`: every point of the file's [sweep] table as its own run (docs/sweeps.md).
struct SweepOptions {
  std::string file;
  std::string out;    // empty: ./<run file stem>
  long jobs = 1;      // points run at once by this process
  long threads = -1;  // per point; -1: the cores shared by the jobs (sweep_command.cpp)
  long index = -1;    // >= 0: run only this point (a Slurm array task)
};
CLI::App* add_sweep_command(CLI::App& app, SweepOptions& options);
int sweep_command(const SweepOptions& options);

// `mresim collect DIR`: the collected tables of a sweep directory.
struct CollectOptions {
  std::string dir;
};
CLI::App* add_collect_command(CLI::App& app, CollectOptions& options);
int collect_command(const CollectOptions& options);

// `run` and `info` refuse a run file with a [sweep] table (ConfigError pointing to `sweep`).
void refuse_sweep_file(const config::TableReader& root, const std::string& file);

CLI::App* add_types_command(CLI::App& app);
int types_command();

// The --threads option of run and resume: an integer in [0, app::max_threads()].
void add_threads_option(CLI::App& command, long& threads);

// The --set KEY=VALUE option of run and info (config/overrides.hpp): repeatable, one argument
// per occurrence, its form checked while the command line is parsed.
void add_set_option(CLI::App& command, std::vector<std::string>& overrides);

// "  name   summary" lines for every registered run type.
std::string run_type_list();

}  // namespace mresim::cli
