#include "mresim/pair/critical_fields.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <utility>

namespace mresim::pair {

int bisection_limit(double range, double tolerance) {
  if (!(range > tolerance) || !(tolerance > 0.0)) return 0;
  const double halvings = std::ceil(std::log2(range / tolerance));
  return static_cast<int>(std::min(halvings, 1100.0));
}

namespace {

struct Bracket {
  double bistable_field;
  PairState rising_state;   // the separated (not yet clustered) branch
  PairState falling_state;  // the clustered branch
  double single_field;      // a field where only one state exists
};

// Validity of one search: the first relaxation that did not converge.
struct Audit {
  bool converged = true;
  std::string problem;
  void check(const PairState& s, const char* where) {
    if (s.converged || !converged) return;
    converged = false;
    problem = fmt::format("relaxation did not converge at B = {:.6g} T ({})", s.field, where);
  }
};

// Two relaxed states are different states when they lie further apart than both the fixed
// threshold and ten times their position errors (what the solver can vouch for).
bool differ(const PairState& a, const PairState& b, const CriticalFieldOptions& opt,
            double radius) {
  const double noise = 10.0 * (a.position_error + b.position_error);
  return (a.separation - b.separation).norm() > std::max(opt.distinct_states * radius, noise);
}

struct Refined {
  double field = 0.0;
  double half_width = 0.0;
};

// Rounds of narrowing both brackets to the scale of dH: each round re-estimates dH; two
// suffice unless dH shrinks a lot as the brackets narrow, and the rounds end earlier when a
// round gains nothing.
constexpr int kMaxDeltaRounds = 8;

// Bisects between a bistable field and a single-state field (narrowing `b` in place); returns
// the midpoint. Stops at bracket width `width`, or when the midpoint is no longer strictly
// between the ends (double precision), and never after more halvings than `width` needs.
Refined refine(const PairSystem& system, Bracket& b, double width, const Eigen::Vector3d& direction,
               const SweepOptions& sweep, const CriticalFieldOptions& opt, Audit& audit) {
  const int limit = bisection_limit(std::abs(b.single_field - b.bistable_field), width);
  for (int i = 0; i < limit && std::abs(b.single_field - b.bistable_field) > width; ++i) {
    const double mid = 0.5 * (b.single_field + b.bistable_field);
    if (mid == b.single_field || mid == b.bistable_field) break;
    const PairState a =
        relax_at_field(system, mid, direction, b.rising_state.separation, sweep.relax);
    const PairState c =
        relax_at_field(system, mid, direction, b.falling_state.separation, sweep.relax);
    audit.check(a, "bisection from the separated branch");
    audit.check(c, "bisection from the clustered branch");
    if (differ(a, c, opt, system.material.radius)) {
      b.bistable_field = mid;
      b.rising_state = a;
      b.falling_state = c;
    } else {
      b.single_field = mid;
    }
  }
  return {0.5 * (b.single_field + b.bistable_field),
          0.5 * std::abs(b.single_field - b.bistable_field)};
}

// Which half of a sweep step the jump lies in, when a trial field holds a single state: that
// state is on the upper end's (clustered) branch, so the jump lies below the trial field, ...
enum class SingleStateRule {
  // ... when it is the upper end's state itself (they do not differ, differ() above). Right
  // near the clustering threshold, where the separated branch runs steeply down to a fold just
  // above contact and the nearer-end rule below mistakes it for the clustered state; wrong
  // where the clustered state itself moves with the field by more than the differ() threshold
  // within the step (a soft WCA wall).
  same_as_upper_end,
  // ... when it lies nearer to the upper end's state than to the lower end's.
  nearer_end,
};

// A bistable range narrower than the sweep step can fall between two grid fields: the rising
// branch then jumps between b_lo and b_hi with no grid field holding two states. Bisect the
// step: at a trial field relax from both ends' states; if they differ the field is bistable
// (returned as a bracket for both ends), otherwise the single state tells (by `rule`) which
// half the jump lies in. Returns nothing if the step holds only a steep but continuous change
// (or `rule` lost the jump).
std::optional<std::pair<Bracket, Bracket>> bistable_inside_step(
    const PairSystem& system, PairState before, PairState after, const Eigen::Vector3d& direction,
    const SweepOptions& sweep, const CriticalFieldOptions& opt, SingleStateRule rule,
    Audit& audit) {
  double b_lo = before.field;
  double b_hi = after.field;
  // Down to the finest bracket, not just the tolerance: a range narrower than the tolerance
  // (dH ~ 1e-5 T near the clustering threshold) is found once the bracket is below twice its
  // width. A continuous (steep but single-valued) change stops the search instead: its ends
  // stop being distinct states as the bracket shrinks.
  const double finest = opt.tolerance * opt.finest_fraction;
  const int limit = bisection_limit(b_hi - b_lo, finest);
  for (int i = 0; i < limit && b_hi - b_lo > finest; ++i) {
    if (!differ(before, after, opt, system.material.radius)) break;
    const double mid = 0.5 * (b_lo + b_hi);
    if (mid == b_lo || mid == b_hi) break;
    const PairState a = relax_at_field(system, mid, direction, before.separation, sweep.relax);
    const PairState c = relax_at_field(system, mid, direction, after.separation, sweep.relax);
    audit.check(a, "search inside a sweep step");
    audit.check(c, "search inside a sweep step");
    if (differ(a, c, opt, system.material.radius)) {
      return std::pair{Bracket{mid, a, c, b_hi}, Bracket{mid, a, c, b_lo}};
    }
    const bool upper_branch =
        rule == SingleStateRule::same_as_upper_end
            ? !differ(a, after, opt, system.material.radius)
            : (a.separation - after.separation).norm() <= (a.separation - before.separation).norm();
    if (upper_branch) {
      b_hi = mid;
      after = a;
    } else {
      b_lo = mid;
      before = a;
    }
  }
  return std::nullopt;
}

// Refines both ends from their brackets into `result`, recording validity.
void refine_both(const PairSystem& system, const Bracket& hc2, const std::optional<Bracket>& hc1,
                 const Eigen::Vector3d& direction, const SweepOptions& sweep,
                 const CriticalFieldOptions& options, Audit& audit, CriticalFields& result) {
  result.hysteresis = true;
  Bracket upper = hc2;
  Refined up = refine(system, upper, options.tolerance, direction, sweep, options, audit);
  result.hc2 = up.field;
  result.uncertainty = up.half_width;
  if (hc1) {
    Bracket lower = *hc1;
    Refined down = refine(system, lower, options.tolerance, direction, sweep, options, audit);
    // The scale of dH sets the final brackets (CriticalFieldOptions::delta_relative): narrow
    // both until their half-widths add up to delta_relative x dH, re-estimating dH each round.
    const double finest = options.tolerance * options.finest_fraction;
    // This is precision beyond the tolerance: a relaxation that fails to converge in it (the
    // softest springs slow down at their folds) ends it and keeps the brackets reached so far,
    // rather than invalidating critical fields that were found to the tolerance.
    for (int round = 0; round < kMaxDeltaRounds; ++round) {
      const double delta = up.field - down.field;
      if (up.half_width + down.half_width <= options.delta_relative * delta) break;
      const double width = std::max(finest, options.delta_relative * delta);
      Audit extra;
      Bracket upper_next = upper;
      Bracket lower_next = lower;
      const Refined u = refine(system, upper_next, width, direction, sweep, options, extra);
      const Refined d = refine(system, lower_next, width, direction, sweep, options, extra);
      if (!extra.converged) break;
      const bool progress = u.half_width < up.half_width || d.half_width < down.half_width;
      upper = upper_next;
      lower = lower_next;
      up = u;
      down = d;
      if (!progress) break;  // at the finest bracket or at double precision
    }
    result.hc2 = up.field;
    result.hc1 = down.field;
    result.uncertainty = std::max(up.half_width, down.half_width);
    result.delta_uncertainty = up.half_width + down.half_width;
    result.delta_resolved = result.delta_uncertainty <= kResolvedFraction * result.delta();
  } else {  // still bistable at zero field: no H_C1 in the swept range
    result.hc1 = 0.0;
    result.in_range = false;
    if (result.problem.empty()) {
      result.problem = "the pair stays clustered at zero field (no H_C1 in [0, field.max])";
    }
  }
  result.converged = audit.converged;
  if (!audit.converged) result.problem = audit.problem;
}

}  // namespace

CriticalFields find_critical_fields(const PairSystem& system, const HysteresisLoop& loop,
                                    const CriticalFieldOptions& options) {
  const SweepOptions& sweep = loop.options;
  const double step = sweep.b_step;
  // First-quadrant states of the rising (branch 0) and falling (branch 1) legs by step index.
  std::map<int, const PairState*> rising;
  std::map<int, const PairState*> falling;
  Audit audit;
  for (const PairState& s : loop.states) {
    const int j = static_cast<int>(std::lround(s.field / step));
    if (j < 0 || s.branch > 1) continue;
    if (s.branch == 0) rising[j] = &s;
    if (s.branch == 1) falling[j] = &s;
    audit.check(s, s.branch == 0 ? "rising branch of the sweep" : "falling branch of the sweep");
  }
  // Steps of the rising branch that move the pair by more than this (in R) are checked for a
  // bistable range narrower than the step.
  constexpr double kJumpFraction = 1e-2;
  int first = -1;
  int last = -1;
  for (const auto& [j, up] : rising) {
    auto down = falling.find(j);
    if (down == falling.end()) continue;
    if (differ(*up, *down->second, options, system.material.radius)) {
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
      auto found = bistable_inside_step(system, lo, hi, direction, sweep, options,
                                        SingleStateRule::same_as_upper_end, audit);
      if (!found) {
        found = bistable_inside_step(system, lo, hi, direction, sweep, options,
                                     SingleStateRule::nearer_end, audit);
      }
      if (!found) continue;
      refine_both(system, found->first, found->second, direction, sweep, options, audit, result);
      return result;
    }
    result.converged = audit.converged;
    result.problem = audit.problem;
    return result;
  }
  auto bracket_at = [&](int j, int neighbour) {
    return Bracket{j * step, *rising.at(j), *falling.at(j), neighbour * step};
  };
  // The falling branch starts one step below field.max, so last + 1 is always a swept field.
  std::optional<Bracket> lower;
  if (first > 0) lower = bracket_at(first, first - 1);
  refine_both(system, bracket_at(last, last + 1), lower, direction, sweep, options, audit, result);
  return result;
}

CriticalFields critical_fields_of(const PairSystem& system, const SweepOptions& sweep,
                                  const CriticalFieldOptions& options) {
  SweepOptions quadrant = sweep;
  quadrant.first_quadrant_only = true;
  return find_critical_fields(system, run_hysteresis(system, quadrant), options);
}

}  // namespace mresim::pair
