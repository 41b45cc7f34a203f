#include "mresim/app/eta.hpp"

#include <algorithm>
#include <cmath>

namespace mresim::app {

void EtaEstimator::start(double now, std::size_t done) {
  last_time_ = now;
  last_done_ = done;
  per_unit_.reset();
}

void EtaEstimator::record(double now, std::size_t done) {
  if (done <= last_done_) return;
  const auto units = static_cast<double>(done - last_done_);
  const double measured = std::max(0.0, now - last_time_) / units;
  if (!per_unit_) {
    per_unit_ = measured;
  } else {
    const double w = 1.0 - std::pow(1.0 - weight_, units);
    per_unit_ = w * measured + (1.0 - w) * *per_unit_;
  }
  last_time_ = now;
  last_done_ = done;
}

std::optional<double> EtaEstimator::remaining(double now, std::size_t total) const {
  if (!per_unit_) return std::nullopt;
  if (last_done_ >= total) return 0.0;
  const auto left = static_cast<double>(total - last_done_);
  // The unit in progress: what the mean leaves of it, at least nothing.
  const double current = std::max(0.0, *per_unit_ - std::max(0.0, now - last_time_));
  return current + (left - 1.0) * *per_unit_;
}

std::optional<double> EtaEstimator::seconds_per_unit() const { return per_unit_; }

}  // namespace mresim::app
