#pragma once

#include <cstddef>
#include <optional>

namespace mresim::app {

// Estimated time to the end of a run from the measured time of the units (steps, grid points)
// finished so far.
//
// The time per unit is an exponentially weighted mean of the measured times: each finished
// unit enters with weight `weight` (a batch of k units finished together with
// 1 - (1 - weight)^k), so the estimate follows a run whose steps grow slower (higher fields,
// larger loads) within a few steps, while one unusually quick or slow step moves it by at most
// `weight` of the difference. Units done before the estimator started (a resumed run) are not
// timed. The unit in progress is expected to take the mean time; once it has taken longer, it
// counts as about to end, so the estimate never grows while a slow step runs, it stalls.
class EtaEstimator {
 public:
  explicit EtaEstimator(double weight = 0.3) : weight_(weight) {}

  // Starts timing at `now` (seconds, any origin), with `done` units already finished.
  void start(double now, std::size_t done);
  // `done` units are finished at `now` (done only grows; a smaller value is ignored).
  void record(double now, std::size_t done);

  // Seconds left at `now` for `total` units; nullopt before the first timed unit.
  [[nodiscard]] std::optional<double> remaining(double now, std::size_t total) const;
  // The weighted mean time per unit (s); nullopt before the first timed unit.
  [[nodiscard]] std::optional<double> seconds_per_unit() const;

 private:
  double weight_;
  double last_time_ = 0.0;
  std::size_t last_done_ = 0;
  std::optional<double> per_unit_;
};

}  // namespace mresim::app
