#include "mresim/magnetism/magnetization_curve.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace mresim::magnetism {

std::vector<SweepPoint> major_loop_sweep(double b_max, double b_step) {
  if (!(std::isfinite(b_max) && b_max > 0.0)) {
    throw std::invalid_argument("major_loop_sweep: b_max must be finite and > 0");
  }
  if (!(std::isfinite(b_step) && b_step > 0.0)) {
    throw std::invalid_argument("major_loop_sweep: b_step must be finite and > 0");
  }
  // The small tolerance keeps e.g. 1.5 / 0.01 = 150.00000000000003 at 150 steps.
  const double steps = std::ceil(b_max / b_step - 1e-9);
  if (!(steps < 1e8)) {
    throw std::invalid_argument("major_loop_sweep: b_max / b_step is too large");
  }
  const long n = std::max(1L, static_cast<long>(steps));
  const auto field = [&](long k) {
    return b_max * static_cast<double>(k) / static_cast<double>(n);
  };

  std::vector<SweepPoint> sweep;
  sweep.reserve(static_cast<std::size_t>(5 * n + 1));
  for (long k = 0; k <= n; ++k) sweep.push_back({field(k), kBranchInitialUp});
  for (long k = n - 1; k >= -n; --k) sweep.push_back({field(k), kBranchDown});
  for (long k = -n + 1; k <= n; ++k) sweep.push_back({field(k), kBranchUp});
  return sweep;
}

}  // namespace mresim::magnetism
