#include "mresim/app/progress.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <utility>

namespace mresim::app {

std::string format_duration(double seconds) {
  if (!(seconds >= 0.0) || !std::isfinite(seconds)) return "?";
  if (seconds < 60.0) return fmt::format("{:.1f}s", seconds);
  const auto whole = static_cast<long long>(seconds);
  if (whole < 3600) return fmt::format("{}m{:02}s", whole / 60, whole % 60);
  return fmt::format("{}h{:02}m", whole / 3600, (whole % 3600) / 60);
}

namespace {

Progress::Clock steady_clock_seconds() {
  return [] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch())
        .count();
  };
}

}  // namespace

Progress::Progress(std::size_t total_units, std::string label)
    : Progress(total_units, std::move(label), Options{}) {}

Progress::Progress(std::size_t total_units, std::string label, Options options)
    : label_(std::move(label)),
      options_(std::move(options)),
      output_(options_.output != nullptr ? options_.output : &run_output()),
      clock_(options_.clock ? options_.clock : steady_clock_seconds()),
      start_(clock_()),
      total_(total_units),
      next_periodic_s_(options_.heartbeat_s) {
  eta_.start(0.0, 0);
}

void Progress::set_total(std::size_t total_units) { total_.store(total_units); }

double Progress::elapsed_seconds() const { return now(); }

void Progress::skip(std::size_t units) {
  const std::lock_guard lock(mutex_);
  const std::size_t done = done_.fetch_add(units) + units;
  eta_.start(now(), done);
  last_periodic_done_.store(done);
}

bool Progress::percent_due(std::size_t done) const {
  const std::size_t total = total_.load();
  // The last unit is reported by finish()'s line.
  if (total == 0 || done >= total || !(options_.percent_step > 0.0)) return false;
  const auto mark = [&](std::size_t n) {
    return std::floor(100.0 * static_cast<double>(n) / static_cast<double>(total) /
                      options_.percent_step);
  };
  return mark(done) > mark(last_periodic_done_.load());
}

void Progress::advance(std::size_t units) {
  const std::size_t done = done_.fetch_add(units) + units;
  const double t = now();
  const bool draw = output().interactive() && t >= next_draw_s_.load();
  if (!draw && t < next_periodic_s_.load() && !percent_due(done)) return;
  // Whoever holds the lock prints; the other threads carry on computing instead of waiting.
  const std::unique_lock lock(mutex_, std::try_to_lock);
  if (!lock.owns_lock() || finished_) return;
  eta_.record(t, done_.load());
  if (!steps_ && (t >= next_periodic_s_.load() || percent_due(done_.load()))) {
    last_periodic_done_.store(done_.load());
    next_periodic_s_.store(t + options_.heartbeat_s);
    output().periodic(percent_line(t));
  }
  if (draw) draw_live(t);
}

void Progress::note(std::string_view line) { output().record(line); }

void Progress::set_residual(std::string name, std::string unit) {
  const std::lock_guard lock(mutex_);
  residual_name_ = std::move(name);
  residual_unit_ = std::move(unit);
}

void Progress::begin_step(std::string what) {
  const std::lock_guard lock(mutex_);
  const double t = now();
  steps_ = true;
  step_what_ = std::move(what);
  step_start_s_ = t;
  step_iteration_ = -1;
  step_residual_ = 0.0;
  next_periodic_s_.store(t + options_.heartbeat_s);
  if (output().interactive()) draw_live(t);
}

void Progress::iteration(std::int64_t iteration, double residual) {
  const double t = now();
  const bool draw = output().interactive() && t >= next_draw_s_.load();
  const bool heartbeat = t >= next_periodic_s_.load();
  const std::lock_guard lock(mutex_);
  step_iteration_ = iteration;
  step_residual_ = residual;
  if (finished_) return;
  if (heartbeat) {
    next_periodic_s_.store(t + options_.heartbeat_s);
    output().periodic(heartbeat_line(t));
  }
  if (draw) draw_live(t);
}

void Progress::end_step(const StepResult& result) {
  const std::lock_guard lock(mutex_);
  const double t = now();
  const std::size_t done = done_.fetch_add(1) + 1;
  eta_.record(t, done);
  const std::size_t total = total_.load();
  std::string line = fmt::format("{}: step {}", label_, done);
  if (total > 0) line += fmt::format("/{}", total);
  if (!step_what_.empty()) line += fmt::format(" ({})", step_what_);
  line += fmt::format(": {} iterations, {}, converged {}, {}", result.iterations,
                      residual_text(result.residual), result.converged ? "yes" : "no",
                      format_duration(result.wall_seconds));
  if (!result.finished_by_fallback.empty()) {
    line += fmt::format(", finished by {}", result.finished_by_fallback);
  }
  output().record(line);
  step_what_.clear();
  step_iteration_ = -1;
  last_periodic_done_.store(done);
  next_periodic_s_.store(t + options_.heartbeat_s);
}

void Progress::finish() {
  const std::lock_guard lock(mutex_);
  if (finished_) return;
  finished_ = true;
  const std::size_t total = total_.load();
  const std::string line = total == 0
                               ? fmt::format("{}: done in {}", label_, format_duration(now()))
                               : fmt::format("{}: done {}/{} in {}", label_, done_.load(), total,
                                             format_duration(now()));
  output().record(line);
}

std::string Progress::step_name() const {
  const std::size_t total = total_.load();
  std::string name =
      fmt::format("step {}", std::min(done_.load() + 1, std::max<std::size_t>(total, 1)));
  if (total > 0) name += fmt::format("/{}", total);
  if (!step_what_.empty()) name += fmt::format(" ({})", step_what_);
  return name;
}

std::string Progress::residual_text(double residual) const {
  std::string text = fmt::format("{} {:.3g}", residual_name_, residual);
  if (!residual_unit_.empty()) text += " " + residual_unit_;
  return text;
}

std::string Progress::live_line(double t) const {
  const std::size_t done = done_.load();
  const std::size_t total = total_.load();
  std::string line = label_ + ": ";
  if (steps_) {
    line += step_name();
    if (step_iteration_ >= 0) {
      line += fmt::format(" iteration {}, {}", step_iteration_, residual_text(step_residual_));
    }
  } else if (total == 0) {
    line += fmt::format("{} done", done);
  } else {
    const double fraction = std::min(1.0, static_cast<double>(done) / static_cast<double>(total));
    line += fmt::format("{:3.0f}% ({}/{})", 100.0 * fraction, done, total);
  }
  line += fmt::format(" | elapsed {}", format_duration(t));
  if (total > 0 && done < total) {
    if (const auto eta = eta_.remaining(t, total)) line += " | ETA " + format_duration(*eta);
  }
  return line;
}

std::string Progress::percent_line(double t) const {
  const std::size_t done = done_.load();
  const std::size_t total = total_.load();
  if (total == 0) {
    return fmt::format("{}: {} done, elapsed {}", label_, done, format_duration(t));
  }
  const double fraction = std::min(1.0, static_cast<double>(done) / static_cast<double>(total));
  std::string line = fmt::format("{}: {:.0f}% ({}/{}), elapsed {}", label_, 100.0 * fraction, done,
                                 total, format_duration(t));
  if (done < total) {
    if (const auto eta = eta_.remaining(t, total)) line += ", ETA " + format_duration(*eta);
  }
  return line;
}

std::string Progress::heartbeat_line(double t) const {
  std::string line = fmt::format("{}: {}: ", label_, step_name());
  if (step_iteration_ >= 0) {
    line += fmt::format("iteration {}, {}, ", step_iteration_, residual_text(step_residual_));
  }
  return line + format_duration(t - step_start_s_) + " in this step";
}

void Progress::draw_live(double t) {
  next_draw_s_.store(t + options_.min_interval_s);
  output().live(live_line(t));
}

}  // namespace mresim::app
