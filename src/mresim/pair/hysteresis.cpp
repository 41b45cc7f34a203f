#include "mresim/pair/hysteresis.hpp"

#include <cmath>
#include <numbers>

namespace mresim::pair {

std::vector<SweepPoint> sweep_points(const SweepOptions& options) {
  const int n = static_cast<int>(std::lround(options.b_max / options.b_step));
  std::vector<SweepPoint> points;
  for (int j = 0; j <= n; ++j) points.push_back({j, 0});
  const int lowest = options.first_quadrant_only ? 0 : -n;
  for (int j = n - 1; j >= lowest; --j) points.push_back({j, 1});
  if (!options.first_quadrant_only) {
    for (int j = -n + 1; j <= n; ++j) points.push_back({j, 2});
  }
  return points;
}

double PairState::rotation_deg() const {
  return std::atan2(separation.z(), separation.x()) * 180.0 / std::numbers::pi;
}

double PairState::magnetization_along(const Eigen::Vector3d& direction) const {
  return magnetization.m.dot(direction);  // (m1 + m2)/2 . h_hat with m1 = m2
}

Eigen::Vector3d rest_configuration(const PairSystem& system) {
  return {system.springs.rest_separation, 0.0, 0.0};
}

PairState relax_at_field(const PairSystem& system, double b, const Eigen::Vector3d& direction,
                         const Eigen::Vector3d& start, const RelaxOptions& options) {
  const PairEnergy energy(system, b * direction);
  const RelaxResult r = relax(energy, system.springs.model, start, options);
  PairState s;
  s.field = b;
  s.separation = r.separation;
  s.magnetization = energy.magnetization(r.separation / energy.length_scale());
  s.energy = energy.breakdown(r.separation / energy.length_scale());
  s.iterations = r.iterations;
  s.converged = r.converged;
  s.position_error = r.position_error;
  return s;
}

HysteresisLoop run_hysteresis(const PairSystem& system, const SweepOptions& options) {
  HysteresisLoop loop;
  loop.options = options;
  const Eigen::Vector3d direction = field_direction(options.theta_h_deg);
  Eigen::Vector3d current = rest_configuration(system);
  for (const SweepPoint& p : sweep_points(options)) {
    PairState s =
        relax_at_field(system, p.step_index * options.b_step, direction, current, options.relax);
    s.branch = p.branch;
    current = s.separation;
    loop.states.push_back(std::move(s));
  }
  return loop;
}

}  // namespace mresim::pair
