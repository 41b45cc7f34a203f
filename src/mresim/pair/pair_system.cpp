#include "mresim/pair/pair_system.hpp"

#include <cmath>
#include <numbers>

namespace mresim::pair {

double SphereMaterial::volume() const {
  return 4.0 / 3.0 * std::numbers::pi * radius * radius * radius;
}

double SphereMaterial::magnetic_energy_scale() const {
  return kMu0 * saturation_magnetization * saturation_magnetization * volume();
}

OverlapPenalty OverlapPenalty::tanh_default(double radius) {
  OverlapPenalty p;
  p.kind = PenaltyKind::tanh;
  p.e_max = 100.0;
  p.delta = 1e-2;
  p.r_min = 2.0 * radius;
  p.r_cut = std::pow(2.0, 1.0 / 6.0) * p.r_min;
  return p;
}

OverlapPenalty OverlapPenalty::wca_default(double radius) {
  OverlapPenalty p = tanh_default(radius);
  p.kind = PenaltyKind::wca;
  p.e_max = 1e-2;
  return p;
}

Eigen::Vector3d field_direction(double theta_h_degrees) {
  const double t = theta_h_degrees * std::numbers::pi / 180.0;
  return {std::cos(t), 0.0, std::sin(t)};
}

}  // namespace mresim::pair
