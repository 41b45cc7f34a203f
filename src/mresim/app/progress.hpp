#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <mutex>
#include <string>
#include <string_view>

#include "mresim/app/eta.hpp"
#include "mresim/app/run_output.hpp"

namespace mresim::app {

// Progress of a long run, written through a RunOutput (run_output.hpp):
//  - on a terminal, a live line redrawn in place at most every 0.5 s: for the 3D runs
//    "hysteresis: step 3/21 (B 0.100 T) iteration 1200, max force 3.2e-09 N | elapsed 4m05s |
//    ETA 10m12s", for the others "pair_map:  42% (420/1000) | elapsed 1m05s | ETA 1m30s";
//  - record lines: one per finished relaxation step (begin_step/end_step) with its iterations,
//    residual, convergence and wall time, and the final "done" line;
//  - periodic lines (log, and stderr when it is not a terminal): a heartbeat every
//    `heartbeat_s` during a step (its iteration and residual so far), and for run types that
//    only count units (maps, sweeps) a line each `percent_step` % or `heartbeat_s`, whichever
//    comes first, never one per unit.
// The ETA is EtaEstimator's (eta.hpp): the measured times of the finished units, weighted
// towards the recent ones.
//
// Progress only reads what it is told: it never changes what a run computes. advance() and
// iteration() may be called from any thread (e.g. inside an OpenMP loop); when nothing is due
// they cost an atomic add, a clock read and a comparison.
class Progress {
 public:
  // Seconds since any fixed origin; tests pass their own to step through time.
  using Clock = std::function<double()>;

  struct Options {
    RunOutput* output = nullptr;  // nullptr: the process's run_output()
    double min_interval_s = 0.5;  // between two redraws of the live line
    double heartbeat_s = 30.0;    // between periodic lines while nothing else is printed
    double percent_step = 10.0;   // periodic line each time this many % more units are done
    Clock clock;                  // default: std::chrono::steady_clock
  };

  // What end_step reports about a relaxation step.
  struct StepResult {
    std::int64_t iterations = 0;
    double residual = 0.0;  // in the unit of set_residual
    bool converged = false;
    double wall_seconds = 0.0;
    // Empty, or the fallback method that finished the step in place of the configured one
    // (the line then ends ", finished by fire").
    std::string finished_by_fallback;
  };

  // total_units = 0 means "unknown yet": the lines then show a count without percent or ETA.
  Progress(std::size_t total_units, std::string label);
  Progress(std::size_t total_units, std::string label, Options options);
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  // For plans that learn the amount of work only once they start.
  void set_total(std::size_t total_units);
  void advance(std::size_t units = 1);
  // Units finished before this process started (a resumed run): counted, not timed.
  void skip(std::size_t units);
  // Prints the final line (once; later calls do nothing).
  void finish();

  // A record line as it is ("mresim: lattice ...").
  void note(std::string_view line);

  // Relaxation steps, one unit each. The residual's name and unit, e.g. "max force", "N".
  void set_residual(std::string name, std::string unit);
  // The step that starts now, described by `what` ("B 0.100 T, strain 0.01").
  void begin_step(std::string what);
  // The running step's solver reached `iteration` with `residual` (the solvers' observer).
  void iteration(std::int64_t iteration, double residual);
  // The running step ended: its record line, and one unit done.
  void end_step(const StepResult& result);

  [[nodiscard]] std::size_t done() const { return done_.load(); }
  [[nodiscard]] std::size_t total() const { return total_.load(); }
  [[nodiscard]] double elapsed_seconds() const;

 private:
  double now() const { return clock_() - start_; }
  RunOutput& output() const { return *output_; }
  // Under mutex_; t is now(), the seconds since the start.
  [[nodiscard]] std::string step_name() const;
  [[nodiscard]] std::string residual_text(double residual) const;
  [[nodiscard]] std::string live_line(double t) const;
  [[nodiscard]] std::string percent_line(double t) const;
  [[nodiscard]] std::string heartbeat_line(double t) const;
  void draw_live(double t);
  // Whether a unit count crossed the next percent mark.
  [[nodiscard]] bool percent_due(std::size_t done) const;

  std::string label_;
  Options options_;
  RunOutput* output_;
  Clock clock_;
  double start_ = 0.0;
  std::atomic<std::size_t> total_;
  std::atomic<std::size_t> done_{0};
  // When the next live redraw or periodic line may happen (s since start): the cheap early-out.
  std::atomic<double> next_draw_s_{0.0};
  std::atomic<double> next_periodic_s_{0.0};
  std::atomic<std::size_t> last_periodic_done_{0};  // written under mutex_

  std::mutex mutex_;  // guards everything below
  EtaEstimator eta_;
  bool steps_ = false;  // begin_step was called: step lines, no percent lines
  std::string step_what_;
  double step_start_s_ = 0.0;
  std::int64_t step_iteration_ = -1;  // -1: no iteration reported yet
  double step_residual_ = 0.0;
  std::string residual_name_ = "residual";
  std::string residual_unit_;
  bool finished_ = false;
};

// "0.4s", "12.3s", "4m05s", "2h03m".
std::string format_duration(double seconds);

}  // namespace mresim::app
