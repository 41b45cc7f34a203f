#include "mresim/app/run_output.hpp"

#include <unistd.h>

#include <memory>

namespace mresim::app {

RunOutput::RunOutput(Options options) : options_(options) {
  if (options_.stream != nullptr) {
    interactive_ = options_.interactive.value_or(::isatty(::fileno(options_.stream)) != 0);
  }
}

void RunOutput::write_stream(std::string_view line) {
  if (options_.stream == nullptr) return;
  // \r returns to the line start, \x1b[K clears what the live line left there.
  if (live_shown_) std::fputs("\r\x1b[K", options_.stream);
  live_shown_ = false;
  std::fprintf(options_.stream, "%.*s\n", static_cast<int>(line.size()), line.data());
  std::fflush(options_.stream);
}

void RunOutput::write_log(std::string_view line) const {
  if (options_.log == nullptr) return;
  std::fprintf(options_.log, "%.*s\n", static_cast<int>(line.size()), line.data());
  std::fflush(options_.log);
}

void RunOutput::record(std::string_view line) {
  const std::lock_guard lock(mutex_);
  write_stream(line);
  write_log(line);
}

void RunOutput::error(std::string_view line) {
  const std::lock_guard lock(mutex_);
  if (options_.error_stream != nullptr) {
    if (live_shown_ && options_.error_stream == options_.stream) {
      std::fputs("\r\x1b[K", options_.stream);
    }
    live_shown_ = false;
    std::fprintf(options_.error_stream, "%.*s\n", static_cast<int>(line.size()), line.data());
    std::fflush(options_.error_stream);
  }
  write_log(line);
}

void RunOutput::periodic(std::string_view line) {
  const std::lock_guard lock(mutex_);
  if (!interactive_) write_stream(line);
  write_log(line);
}

void RunOutput::live(std::string_view line) {
  const std::lock_guard lock(mutex_);
  if (!interactive_) return;
  std::fprintf(options_.stream, "\r%.*s\x1b[K", static_cast<int>(line.size()), line.data());
  std::fflush(options_.stream);
  live_shown_ = true;
}

void RunOutput::clear_live() {
  const std::lock_guard lock(mutex_);
  if (!live_shown_) return;
  std::fputs("\r\x1b[K", options_.stream);
  std::fflush(options_.stream);
  live_shown_ = false;
}

namespace {
std::unique_ptr<RunOutput>& process_output() {
  static std::unique_ptr<RunOutput> output = std::make_unique<RunOutput>();
  return output;
}
}  // namespace

RunOutput& run_output() { return *process_output(); }

void configure_run_output(const RunOutput::Options& options) {
  process_output() = std::make_unique<RunOutput>(options);
}

void warn(std::string_view message) {
  run_output().record(std::string("mresim: warning: ").append(message));
}

}  // namespace mresim::app
