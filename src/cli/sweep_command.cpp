// `mresim sweep FILE --out DIR`: every point of the run file's [sweep] table as one `mresim run`
// child process, spread over local cores (--jobs), MPI ranks (mpirun) or Slurm array tasks
// (--index); then the summary and `mresim collect DIR`. docs/sweeps.md.

#include <fmt/format.h>
#include <omp.h>
#include <toml++/toml.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <limits>
#include <string>
#include <thread>
#include <vector>

#include "cli/commands.hpp"
#include "cli/exit_status.hpp"
#include "cli/mpi_world.hpp"
#include "cli/sweep_child.hpp"
#include "mresim/app/run_type.hpp"
#include "mresim/app/stop_signal.hpp"
#include "mresim/app/threads.hpp"
#include "mresim/config/config_error.hpp"
#include "mresim/config/table_reader.hpp"
#include "mresim/sweep/collect.hpp"
#include "mresim/sweep/sweep_directory.hpp"
#include "mresim/sweep/sweep_spec.hpp"

namespace mresim::cli {

namespace fs = std::filesystem;

namespace {

// What became of one point in this invocation; summed over the ranks (0: not this rank's).
constexpr int kNotMine = 0;
constexpr int kSkipped = 1;     // already finished
constexpr int kNotStarted = 2;  // a stop signal came first
constexpr int kExitBase = 3;    // ran: kExitBase + its exit status

std::string parameters_text(const sweep::SweepPoint& point) {
  return fmt::format("{}", fmt::join(point.overrides, ", "));
}

// Expands and validates every point before anything runs: the run file without [sweep] plus the
// point's values as --set overrides, checked by the run type's plan exactly as `mresim run`.
sweep::SweepSpec read_and_validate(const std::string& file) {
  const auto file_reader = config::TableReader::parse_file(file);  // syntax errors as for run
  const toml::table root = toml::parse(file_reader.source_text(), file);
  if (!sweep::has_sweep(root)) {
    throw config::ConfigError(fmt::format(
        "{} has no [sweep] table (docs/sweeps.md); run it with 'mresim run {}'", file, file));
  }
  sweep::SweepSpec spec = sweep::expand_sweep(root);
  for (const sweep::SweepPoint& point : spec.points) {
    try {
      const auto reader = config::TableReader::parse_string(spec.base_text, file, point.overrides);
      (void)app::make_plan(reader);
    } catch (const config::ConfigError& e) {
      throw config::ConfigError(fmt::format("[sweep] point {} of {} ({}): {}", point.index,
                                            spec.points.size(), parameters_text(point), e.what()));
    }
  }
  return spec;
}

// Threads per point: the cores this process may use, shared by its parallel points and, when
// mpirun did not bind the ranks to cores, by the other ranks on this machine. 0 (pass nothing;
// the run's own default) when one point has the machine to itself.
long default_threads(long jobs, const MpiWorld& world) {
  const int usable = omp_get_num_procs();  // honours the affinity mask (Slurm, mpirun binding)
  const unsigned hardware = std::thread::hardware_concurrency();
  const bool bound = hardware > 0 && static_cast<unsigned>(usable) < hardware;
  const long sharing = jobs * (bound ? 1 : world.local_size());
  if (sharing <= 1) return -1;
  return std::max(1L, usable / sharing);
}

int run_point(const sweep::SweepSpec& spec, const sweep::SweepPoint& point, const fs::path& dir,
              long threads) {
  const std::size_t count = spec.points.size();
  const std::string name = sweep::point_name(point.index, count);
  std::vector<std::string> args = {
      own_executable().string(), "run",      (dir / sweep::kBaseFile).string(), "--out",
      (dir / name).string(),     "--no-plot"};
  if (threads >= 0) {
    args.emplace_back("--threads");
    args.push_back(std::to_string(threads));
  }
  for (const std::string& o : point.overrides) {
    args.emplace_back("--set");
    args.push_back(o);
  }
  const fs::path log = sweep::log_file(dir, point.index, count);
  std::error_code ec;
  fs::remove(log, ec);  // the log of this attempt only
  const auto started = std::chrono::steady_clock::now();
  const int status = run_child(args, log);
  sweep::write_point_status(dir, point.index, count, status);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  const sweep::PointState state = sweep::point_state(dir, point.index, count);
  std::printf("mresim sweep: %s (%s): %s, exit status %d, %.1f s%s%s\n", name.c_str(),
              parameters_text(point).c_str(), sweep::status_name(state.status), status, seconds,
              state.message.empty() ? "" : ": ", state.message.c_str());
  std::fflush(stdout);
  return status;
}

// Runs `mine` (indices into spec.points), `jobs` at a time; each entry of the result is an
// Outcome for that point.
std::vector<int> run_points(const sweep::SweepSpec& spec, const std::vector<std::size_t>& mine,
                            const fs::path& dir, long jobs, long threads) {
  std::vector<int> outcome(spec.points.size(), kNotMine);
  const auto n = static_cast<long>(mine.size());
  const auto at_once = static_cast<int>(jobs);
  // OpenMP's dynamic schedule hands the next point to whichever job finishes first; each
  // iteration only starts a child process and waits for it.
#pragma omp parallel for schedule(dynamic, 1) num_threads(at_once)
  for (long k = 0; k < n; ++k) {
    const sweep::SweepPoint& point = spec.points[mine[static_cast<std::size_t>(k)]];
    const std::size_t count = spec.points.size();
    if (io::RunDirectory::is_run_directory(dir / sweep::point_name(point.index, count))) {
      outcome[point.index] = kSkipped;
    } else if (app::stop_requested()) {
      outcome[point.index] = kNotStarted;
    } else {
      // Nothing may leave an OpenMP iteration, and under MPI every rank must reach the final
      // reduction: a failure of the bookkeeping (a log or status file that cannot be written)
      // counts as a failure of the point.
      try {
        outcome[point.index] = kExitBase + run_point(spec, point, dir, threads);
      } catch (const std::exception& e) {
        std::fprintf(stderr, "mresim: error: sweep point %zu: %s\n", point.index, e.what());
        outcome[point.index] = kExitBase + kFailure;
      }
    }
  }
  return outcome;
}

// Rank 0's last words: one line per point that did not succeed, one line of counts. Returns
// the exit status of the sweep.
int report(const sweep::SweepSpec& spec, const std::vector<int>& outcome,
           const std::vector<std::size_t>& chosen, const fs::path& dir) {
  std::size_t skipped = 0;
  std::size_t ran = 0;
  std::size_t failed = 0;
  std::size_t not_started = 0;
  int stop = 0;
  for (const std::size_t i : chosen) {
    const int o = outcome[i];
    if (o == kSkipped) ++skipped;
    if (o == kNotStarted) ++not_started;
    if (o < kExitBase) continue;
    ++ran;
    const int status = o - kExitBase;
    if (status == 130 || status == 143) stop = status;
    if (status == kSuccess) continue;
    ++failed;
    const auto& point = spec.points[i];
    std::fprintf(stderr, "mresim: error: sweep point %zu (%s) failed with exit status %d; see %s\n",
                 i, parameters_text(point).c_str(), status,
                 sweep::log_file(dir, i, spec.points.size()).string().c_str());
  }
  std::printf(
      "mresim sweep: %zu point(s): %zu ran, %zu failed, %zu already finished (skipped), %zu not "
      "started; results in %s\n",
      chosen.size(), ran, failed, skipped, not_started, dir.string().c_str());
  std::fflush(stdout);
  if (app::stop_requested() && stop == 0) stop = 128 + app::stop_signal();
  if (stop != 0) return stop;
  return failed == 0 && not_started == 0 ? kSuccess : kFailure;
}

// An integer option in [min, max]: "VALUE: must be an integer from MIN to MAX (WHAT)".
CLI::Validator integer_between(long min, long max, const char* what) {
  return {[=](std::string& value) -> std::string {
            try {
              std::size_t used = 0;
              const long n = std::stol(value, &used);
              if (used == value.size() && n >= min && n <= max) return "";
            } catch (const std::exception&) {  // not a number, or out of long's range
            }
            return fmt::format("{}: must be an integer from {} to {} ({})", value, min, max, what);
          },
          "INT", what};
}

}  // namespace

CLI::App* add_sweep_command(CLI::App& app, SweepOptions& options) {
  CLI::App* sweep = app.add_subcommand(
      "sweep",
      "Run every point of the [sweep] table of a run file, one run directory each "
      "(docs/sweeps.md)");
  sweep->add_option("FILE", options.file, "Run file (TOML) with a [sweep] table")->required();
  sweep->add_option("--out,-o", options.out,
                    "Sweep directory (default: ./<FILE without extension>); points go to "
                    "DIR/point-NNNN/, finished ones are skipped when run again");
  sweep->add_option("--jobs", options.jobs, "Points run at once on this machine (default 1)")
      ->check(integer_between(1, 1024, "points at once"));
  add_threads_option(*sweep, options.threads);
  sweep->get_option("--threads")
      ->description(
          "Threads per point; 0 = all cores (default: the usable cores / the points running at "
          "once on this machine; with one at a time, [run].threads, else all cores)");
  sweep
      ->add_option("--index", options.index,
                   "Run only point I (0-based), e.g. $SLURM_ARRAY_TASK_ID; no collect")
      ->check(integer_between(0, std::numeric_limits<int>::max(), "a point number"));
  sweep->footer(
      "Exit status: 0 every point finished; 1 a point failed or was not started (the others'\n"
      "results are kept); 2 invalid run file, [sweep] table or command line (nothing ran);\n"
      "130/143 stopped by SIGINT/SIGTERM (run the same command again to continue).");
  return sweep;
}

int sweep_command(const SweepOptions& options) {
  MpiWorld world;
  const sweep::SweepSpec spec = read_and_validate(options.file);
  const std::size_t count = spec.points.size();
  if (options.index >= 0 && static_cast<std::size_t>(options.index) >= count) {
    throw config::ConfigError(fmt::format("--index {}: the sweep has {} point(s), numbered 0 to {}",
                                          options.index, count, count - 1));
  }
  const fs::path dir = options.out.empty() ? fs::path(options.file).stem() : fs::path(options.out);

  // Rank 0 prepares the directory; the others wait for it and stop quietly if it failed (rank
  // 0 reports why).
  int prepared = 1;
  if (world.rank() == 0) {
    try {
      sweep::prepare_sweep_directory(dir, spec, options.file);
    } catch (...) {
      (void)world.broadcast(0);
      throw;
    }
  }
  prepared = world.broadcast(prepared);
  if (prepared == 0) return kInvalidInput;

  // Points of this rank: the one --index names (on rank 0), or every size-th from its rank.
  std::vector<std::size_t> chosen;
  if (options.index >= 0) {
    chosen.push_back(static_cast<std::size_t>(options.index));
  } else {
    for (std::size_t i = 0; i < count; ++i) chosen.push_back(i);
  }
  std::vector<std::size_t> mine;
  for (std::size_t k = 0; k < chosen.size(); ++k) {
    if (static_cast<int>(k % static_cast<std::size_t>(world.size())) == world.rank()) {
      mine.push_back(chosen[k]);
    }
  }
  const long threads =
      options.threads >= 0 ? options.threads : default_threads(options.jobs, world);
  const std::vector<int> outcome =
      world.sum_on_root(run_points(spec, mine, dir, options.jobs, threads));
  if (world.rank() != 0) return kSuccess;

  const int status = report(spec, outcome, chosen, dir);
  if (options.index < 0) {
    const sweep::CollectResult collected = sweep::collect(dir);
    std::printf("mresim sweep: collected tables of %zu finished point(s): %s/collected_*.csv, %s\n",
                collected.finished, dir.string().c_str(),
                collected.written.back().string().c_str());
  }
  return status;
}

}  // namespace mresim::cli
