#include "mresim/magnetism/loop_features.hpp"

#include <cstddef>
#include <optional>
#include <stdexcept>
#include <vector>

namespace mresim::magnetism {

namespace {

// x where y(x) crosses zero from y > 0 to y <= 0 along the descending branch, interpolating
// the other coordinate linearly; nullopt if it never does.
std::optional<double> first_descending_crossing(const MagnetizationCurve& curve,
                                                const std::vector<double>& y,
                                                const std::vector<double>& x) {
  for (std::size_t i = 1; i < y.size(); ++i) {
    if (curve.branch[i] != kBranchDown) continue;
    if (y[i - 1] > 0.0 && y[i] <= 0.0) {
      const double t = y[i - 1] / (y[i - 1] - y[i]);  // in (0, 1]
      return x[i - 1] + t * (x[i] - x[i - 1]);
    }
  }
  return std::nullopt;
}

}  // namespace

LoopFeatures loop_features(const MagnetizationCurve& curve) {
  if (curve.b_tesla.size() != curve.m_over_ms.size() ||
      curve.b_tesla.size() != curve.branch.size()) {
    throw std::invalid_argument("loop_features: curve vectors differ in length");
  }
  const std::optional<double> remanence =
      first_descending_crossing(curve, curve.b_tesla, curve.m_over_ms);
  if (!remanence) throw std::invalid_argument("loop_features: descending branch misses B = 0");
  const std::optional<double> coercive_b =
      first_descending_crossing(curve, curve.m_over_ms, curve.b_tesla);
  if (!coercive_b) throw std::invalid_argument("loop_features: descending branch misses M = 0");
  return LoopFeatures{-*coercive_b, *remanence};
}

}  // namespace mresim::magnetism
