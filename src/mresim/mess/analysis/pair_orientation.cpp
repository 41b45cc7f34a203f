#include "mresim/mess/analysis/pair_orientation.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <limits>

namespace mresim::mess_analysis {

ClosestPair closest_pair(const Eigen::Matrix3Xd& centres) {
  ClosestPair best;
  double best_squared = std::numeric_limits<double>::infinity();
  for (Eigen::Index i = 0; i < centres.cols(); ++i) {
    for (Eigen::Index j = i + 1; j < centres.cols(); ++j) {
      const double d2 = (centres.col(j) - centres.col(i)).squaredNorm();
      if (d2 < best_squared) {
        best_squared = d2;
        best = {i, j, 0.0};
      }
    }
  }
  if (best.first >= 0) best.distance = std::sqrt(best_squared);
  return best;
}

double pair_angle(const Eigen::Matrix3Xd& centres, const Eigen::Vector3d& axis) {
  if (centres.cols() < 2 || !centres.allFinite()) return std::numeric_limits<double>::quiet_NaN();
  const ClosestPair p = closest_pair(centres);
  const Eigen::Vector3d r = centres.col(p.second) - centres.col(p.first);
  // atan2 of sine and cosine parts rather than acos of the cosine: acos loses the angle near
  // 0 (a pair tilted by 1e-8 rad has cos = 1 to double precision).
  return std::atan2(r.cross(axis).norm(), std::abs(r.dot(axis)));
}

}  // namespace mresim::mess_analysis
