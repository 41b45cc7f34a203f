#pragma once

// Two dipoles joined by a single spring, and the analytic release field of such a pair, for
// the tests of the two-dipole model's critical fields.

#include <cmath>

#include "../support/dissertation_values.hpp"
#include "mresim/core/constants.hpp"
#include "mresim/pair/pair_system.hpp"

namespace mresim::pair::testing {

// Spring constant k (N/m), rest separation s0 (m; 9e-6 is the Fig. 2.2 geometry), the overlap
// penalty's default for R = 1.5 um.
inline PairSystem single_spring(double k, double s0, PenaltyKind penalty = PenaltyKind::tanh) {
  PairSystem s;
  s.springs = {SpringModel::single, k, 0.0, s0};
  s.penalty = penalty == PenaltyKind::tanh ? OverlapPenalty::tanh_default(mresim::testing::kR)
                                           : OverlapPenalty::wca_default(mresim::testing::kR);
  return s;
}

// The release field of a clustered pair along the field (the axis) at the contact distance
// `contact`: the clustered state stops being a minimum when the dipole attraction at s_c falls
// below the spring force, 2 m^2 / s_c^4 = k~ (s0 - s_c) with the linear moment
// m = chi h / (1 - 2 chi a) (units of R and mu0 Ms^2 V; k~ from the pair's k12).
inline double analytic_release_field(const PairSystem& p, double contact) {
  const SphereMaterial& mat = p.material;
  const double sc = contact / mat.radius;
  const double s0 = p.springs.rest_separation / mat.radius;
  const double k = p.springs.k12 * mat.radius * mat.radius / mat.magnetic_energy_scale();
  const double m = std::sqrt(0.5 * k * (s0 - sc) * std::pow(sc, 4));
  const double a = 1.0 / (3.0 * sc * sc * sc);
  return m * (1.0 - 2.0 * mat.susceptibility * a) / mat.susceptibility * kMu0 *
         mat.saturation_magnetization;
}

}  // namespace mresim::pair::testing
