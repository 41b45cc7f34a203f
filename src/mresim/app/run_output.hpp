#pragma once

#include <cstdio>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>

namespace mresim::app {

// Where the messages of a run go: stderr (unless --quiet) and, with --log FILE, a log file.
//
// Two kinds of lines:
//  - record lines (set-up, a finished step, warnings, the final line) go to stderr and the log;
//  - periodic lines (heartbeats during a long step, "40% done" of a map) go to the log, and to
//    stderr only when stderr is not a terminal; a terminal shows the live line instead, which
//    is redrawn in place and never reaches the log.
// Every line is flushed at once, so a log read during the run, or left by a run that was
// killed, holds everything up to that moment. All members may be called from any thread.
class RunOutput {
 public:
  struct Options {
    std::FILE* stream = stderr;        // nullptr: nothing on stderr (--quiet)
    std::optional<bool> interactive;   // default: whether `stream` is a terminal
    std::FILE* log = nullptr;          // --log FILE; not owned
    std::FILE* error_stream = stderr;  // errors, also with --quiet
  };

  RunOutput() : RunOutput(Options{}) {}
  explicit RunOutput(Options options);

  // Whether stderr shows a live line (a terminal, not --quiet).
  [[nodiscard]] bool interactive() const { return interactive_; }
  // --quiet: nothing but errors.
  [[nodiscard]] bool quiet() const { return options_.stream == nullptr; }

  void record(std::string_view line);
  // An error line: on the error stream even with --quiet, and in the log.
  void error(std::string_view line);
  void periodic(std::string_view line);
  // Redraws the live line (terminal only); the next record line first clears it.
  void live(std::string_view line);
  // Ends the live line: clears it so that what follows starts on an empty line.
  void clear_live();

 private:
  void write_stream(std::string_view line);
  void write_log(std::string_view line) const;

  Options options_;
  bool interactive_ = false;
  bool live_shown_ = false;
  std::mutex mutex_;
};

// The process's run output: stderr until the command line configures it (run and resume do,
// before anything is read).
RunOutput& run_output();
void configure_run_output(const RunOutput::Options& options);

// "mresim: warning: <message>" as a record line of run_output(), when it happens.
void warn(std::string_view message);

}  // namespace mresim::app
