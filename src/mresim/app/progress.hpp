#pragma once

#include <atomic>
#include <chrono>
#include <cstddef>
#include <cstdio>
#include <mutex>
#include <optional>
#include <string>

namespace mresim::app {

// Progress of a long run on stderr: "hysteresis: 42% (420/1000)  elapsed 1m05s  ETA 1m30s".
//
// On a terminal the line is redrawn in place at most every 0.5 s; when stderr is a file or a
// pipe (batch jobs, CI) nothing is printed until finish(), which prints one final line, so logs
// stay readable. advance() may be called from any thread (e.g. inside an OpenMP loop); it costs
// one atomic add and a clock read.
class Progress {
 public:
  struct Options {
    std::FILE* stream = stderr;       // nullptr: print nothing at all
    std::optional<bool> interactive;  // default: whether `stream` is a terminal
    double min_interval_s = 0.5;      // between two redraws
  };

  // total_units = 0 means "unknown yet": the line then shows a count without percent or ETA.
  Progress(std::size_t total_units, std::string label);
  Progress(std::size_t total_units, std::string label, Options options);
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  // For plans that learn the amount of work only once they start.
  void set_total(std::size_t total_units);
  void advance(std::size_t units = 1);
  // Prints the final line (once; later calls do nothing).
  void finish();

  [[nodiscard]] std::size_t done() const { return done_.load(); }
  [[nodiscard]] std::size_t total() const { return total_.load(); }
  [[nodiscard]] double elapsed_seconds() const;

 private:
  [[nodiscard]] std::string status_line() const;

  std::string label_;
  Options options_;
  bool interactive_ = false;
  std::chrono::steady_clock::time_point start_;
  std::atomic<std::size_t> total_;
  std::atomic<std::size_t> done_{0};
  std::atomic<double> last_draw_s_{0.0};
  std::mutex draw_mutex_;
  bool finished_ = false;
};

// "0.4s", "12.3s", "4m05s", "2h03m".
std::string format_duration(double seconds);

}  // namespace mresim::app
