#include "mresim/pair/critical_fields.hpp"

#include <cmath>
#include <map>
#include <optional>
#include <utility>

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

// A bistable range narrower than the sweep step can fall between two grid fields: the rising
// branch then jumps between b_lo and b_hi with no grid field holding two states. Bisect the
// step: at a trial field relax from both ends' states; if they differ the field is bistable
// (returned as a bracket for both ends), otherwise the single state tells which half the jump
// lies in. Returns nothing if the step holds only a steep but continuous change.
std::optional<std::pair<Bracket, Bracket>> bistable_inside_step(const PairSystem& system,
                                                                double b_lo, Eigen::Vector3d before,
                                                                double b_hi, Eigen::Vector3d after,
                                                                const Eigen::Vector3d& direction,
                                                                const SweepOptions& sweep,
                                                                const CriticalFieldOptions& opt) {
  const double distinct = opt.distinct_states * system.material.radius;
  while (b_hi - b_lo > opt.tolerance) {
    const double mid = 0.5 * (b_lo + b_hi);
    const PairState a = relax_at_field(system, mid, direction, before, sweep.relax);
    const PairState c = relax_at_field(system, mid, direction, after, sweep.relax);
    if ((a.separation - c.separation).norm() > distinct) {
      return std::pair{Bracket{mid, a.separation, c.separation, b_hi},
                       Bracket{mid, a.separation, c.separation, b_lo}};
    }
    if ((a.separation - before).norm() < (a.separation - after).norm()) {
      b_lo = mid;
      before = a.separation;
    } else {
      b_hi = mid;
      after = a.separation;
    }
  }
  return std::nullopt;
}

}  // namespace

CriticalFields find_critical_fields(const PairSystem& system, const HysteresisLoop& loop,
                                    const CriticalFieldOptions& options) {
  const SweepOptions& sweep = loop.options;
  const double step = sweep.b_step;
  // First-quadrant states of the rising (branch 0) and falling (branch 1) legs by step index.
  std::map<int, const PairState*> rising;
  std::map<int, const PairState*> falling;
  for (const PairState& s : loop.states) {
    const int j = static_cast<int>(std::lround(s.field / step));
    if (j < 0) continue;
    if (s.branch == 0) rising[j] = &s;
    if (s.branch == 1) falling[j] = &s;
  }
  const double distinct = options.distinct_states * system.material.radius;
  // Steps of the rising branch that move the pair by more than this (in R) are checked for a
  // bistable range narrower than the step.
  constexpr double kJumpFraction = 1e-2;
  int first = -1;
  int last = -1;
  for (const auto& [j, up] : rising) {
    auto down = falling.find(j);
    if (down == falling.end()) continue;
    if ((up->separation - down->second->separation).norm() > distinct) {
      if (first < 0) first = j;
      last = j;
    }
  }
  CriticalFields result;
  const Eigen::Vector3d direction = field_direction(sweep.theta_h_deg);
  if (first < 0) {
    // No grid field is bistable; look for a jump of the rising branch that hides a narrow
    // bistable range (small S0, where dH is below the sweep step).
    const double jump = kJumpFraction * system.material.radius;
    for (auto it = rising.begin(); std::next(it) != rising.end(); ++it) {
      const PairState& lo = *it->second;
      const PairState& hi = *std::next(it)->second;
      if ((hi.separation - lo.separation).norm() <= jump) continue;
      const auto found = bistable_inside_step(system, lo.field, lo.separation, hi.field,
                                              hi.separation, direction, sweep, options);
      if (!found) continue;
      result.hysteresis = true;
      result.hc2 = refine(system, found->first, direction, sweep, options);
      result.hc1 = refine(system, found->second, direction, sweep, options);
      result.uncertainty = 0.5 * options.tolerance;
      return result;
    }
    return result;
  }
  result.hysteresis = true;
  auto bracket_at = [&](int j, int neighbour) {
    return Bracket{j * step, rising.at(j)->separation, falling.at(j)->separation, neighbour * step};
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
