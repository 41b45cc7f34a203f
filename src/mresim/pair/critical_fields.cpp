#include "mresim/pair/critical_fields.hpp"

#include <cmath>
#include <map>

namespace mresim::pair {
namespace {

struct Bracket {
  double bistable_field;
  Eigen::Vector3d rising_state;   // the separated (not yet clustered) branch
  Eigen::Vector3d falling_state;  // the clustered branch
  double single_field;            // a field where only one state exists
};

// Bisects between a bistable field and a single-state field; returns the midpoint.
double refine(const PairSystem& system, Bracket b, const Eigen::Vector3d& direction,
              const SweepOptions& sweep, const CriticalFieldOptions& opt) {
  const double distinct = opt.distinct_states * system.material.radius;
  while (std::abs(b.single_field - b.bistable_field) > opt.tolerance) {
    const double mid = 0.5 * (b.single_field + b.bistable_field);
    const PairState a = relax_at_field(system, mid, direction, b.rising_state, sweep.relax);
    const PairState c = relax_at_field(system, mid, direction, b.falling_state, sweep.relax);
    if ((a.separation - c.separation).norm() > distinct) {
      b.bistable_field = mid;
      b.rising_state = a.separation;
      b.falling_state = c.separation;
    } else {
      b.single_field = mid;
    }
  }
  return 0.5 * (b.single_field + b.bistable_field);
}

}  // namespace

CriticalFields find_critical_fields(const PairSystem& system, const HysteresisLoop& loop,
                                    const CriticalFieldOptions& options) {
  const SweepOptions& sweep = loop.options;
  const double step = sweep.b_step;
  // First-quadrant states of the rising (branch 0) and falling (branch 1) legs by step index.
  std::map<int, const PairState*> rising, falling;
  for (const PairState& s : loop.states) {
    const int j = static_cast<int>(std::lround(s.field / step));
    if (j < 0) continue;
    if (s.branch == 0) rising[j] = &s;
    if (s.branch == 1) falling[j] = &s;
  }
  const double distinct = options.distinct_states * system.material.radius;
  int first = -1, last = -1;
  for (const auto& [j, up] : rising) {
    auto down = falling.find(j);
    if (down == falling.end()) continue;
    if ((up->separation - down->second->separation).norm() > distinct) {
      if (first < 0) first = j;
      last = j;
    }
  }
  CriticalFields result;
  if (first < 0) return result;
  result.hysteresis = true;
  const Eigen::Vector3d direction = field_direction(sweep.theta_h_deg);
  auto bracket_at = [&](int j, int neighbour) {
    return Bracket{j * step, rising.at(j)->separation, falling.at(j)->separation,
                   neighbour * step};
  };
  result.hc2 = refine(system, bracket_at(last, last + 1), direction, sweep, options);
  result.hc1 = refine(system, bracket_at(first, first - 1), direction, sweep, options);
  result.uncertainty = 0.5 * options.tolerance;
  return result;
}

CriticalFields critical_fields_of(const PairSystem& system, const SweepOptions& sweep,
                                  const CriticalFieldOptions& options) {
  SweepOptions quadrant = sweep;
  quadrant.first_quadrant_only = true;
  return find_critical_fields(system, run_hysteresis(system, quadrant), options);
}

}  // namespace mresim::pair
