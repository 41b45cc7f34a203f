#include "mresim/app/progress.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <cmath>

namespace mresim::app {

std::string format_duration(double seconds) {
  if (!(seconds >= 0.0) || !std::isfinite(seconds)) return "?";
  if (seconds < 60.0) return fmt::format("{:.1f}s", seconds);
  const auto whole = static_cast<long long>(seconds);
  if (whole < 3600) return fmt::format("{}m{:02}s", whole / 60, whole % 60);
  return fmt::format("{}h{:02}m", whole / 3600, (whole % 3600) / 60);
}

Progress::Progress(std::size_t total_units, std::string label)
    : Progress(total_units, std::move(label), Options{}) {}

Progress::Progress(std::size_t total_units, std::string label, Options options)
    : label_(std::move(label)),
      options_(options),
      start_(std::chrono::steady_clock::now()),
      total_(total_units) {
  if (options_.stream != nullptr) {
    interactive_ = options_.interactive.value_or(::isatty(::fileno(options_.stream)) != 0);
  }
}

void Progress::set_total(std::size_t total_units) { total_.store(total_units); }

double Progress::elapsed_seconds() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

std::string Progress::status_line() const {
  const std::size_t done = done_.load();
  const std::size_t total = total_.load();
  const double elapsed = elapsed_seconds();
  if (total == 0)
    return fmt::format("{}: {} done  elapsed {}", label_, done, format_duration(elapsed));
  const double fraction = std::min(1.0, static_cast<double>(done) / static_cast<double>(total));
  std::string line = fmt::format("{}: {:3.0f}% ({}/{})  elapsed {}", label_, 100.0 * fraction, done,
                                 total, format_duration(elapsed));
  if (done > 0 && done < total) {
    line += fmt::format("  ETA {}", format_duration(elapsed * (1.0 - fraction) / fraction));
  }
  return line;
}

void Progress::advance(std::size_t units) {
  done_.fetch_add(units);
  if (!interactive_) return;
  const double now = elapsed_seconds();
  if (now - last_draw_s_.load() < options_.min_interval_s) return;
  // Whoever holds the lock draws; the other threads carry on computing instead of waiting.
  const std::unique_lock lock(draw_mutex_, std::try_to_lock);
  if (!lock.owns_lock() || finished_) return;
  last_draw_s_.store(now);
  // \r returns to the line start, \x1b[K clears what a longer previous line left behind.
  std::fprintf(options_.stream, "\r%s\x1b[K", status_line().c_str());
  std::fflush(options_.stream);
}

void Progress::finish() {
  const std::lock_guard lock(draw_mutex_);
  if (finished_ || options_.stream == nullptr) {
    finished_ = true;
    return;
  }
  finished_ = true;
  const std::size_t total = total_.load();
  const std::string line =
      total == 0 ? fmt::format("{}: done in {}", label_, format_duration(elapsed_seconds()))
                 : fmt::format("{}: done {}/{} in {}", label_, done_.load(), total,
                               format_duration(elapsed_seconds()));
  std::fprintf(options_.stream, interactive_ ? "\r%s\x1b[K\n" : "%s\n", line.c_str());
  std::fflush(options_.stream);
}

}  // namespace mresim::app
