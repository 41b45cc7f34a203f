#pragma once

#include <string>

#include "mresim/pair/hysteresis.hpp"

namespace mresim::pair {

// Critical fields of the bistable range (Section 2.5.1), as magnitudes of B = mu0 H in tesla
// on the first quadrant: the pair clusters at +H_C2 on the rising branch and separates at
// +H_C1 on the falling branch; dH = H_C2 - H_C1. (By symmetry the negative-field critical
// fields are -H_C2 and -H_C1.)
struct CriticalFields {
  bool hysteresis = false;
  double hc1 = 0.0;
  double hc2 = 0.0;
  double uncertainty = 0.0;  // half-width of the widest final bracket, T
  // dH's own error bound: the two final brackets' half-widths added, T (0 without hysteresis).
  double delta_uncertainty = 0.0;
  // dH is resolved when delta_uncertainty <= kResolvedFraction dH: the refinement narrows the
  // brackets below the tolerance until dH is known to CriticalFieldOptions::delta_relative of
  // itself, so this is false only where that would need brackets finer than
  // tolerance x finest_fraction (or than doubles resolve). Such a dH is a bound, not a value
  // (it is at most 2 delta_uncertainty). True without hysteresis (nothing to resolve).
  bool delta_resolved = true;
  // Every relaxation used in locating them (the sweep's first quadrant and each bisection's)
  // converged. If not, the fields may be far off (a state stuck at a wall) and must not be
  // taken as results.
  bool converged = true;
  // Both lie in the swept range [0, field.max]. A pair still clustered at zero field has no
  // H_C1 there (reported as 0): in this model it always separates at zero field (no remanence,
  // the spring pushes it apart), so that is a failed relaxation too.
  bool in_range = true;
  std::string problem;  // the first reason the fields are not valid, for messages
  bool valid() const { return converged && in_range; }
  double delta() const { return hysteresis ? hc2 - hc1 : 0.0; }
};

// dH counts as resolved when its error bound is at most this fraction of it.
inline constexpr double kResolvedFraction = 0.1;

struct CriticalFieldOptions {
  double tolerance = 1e-4;  // T, width of the final bracket (at most; see delta_relative)
  // The scale of dH sets the final brackets too: after reaching `tolerance`, both ends are
  // bisected further until their half-widths add up to at most delta_relative x dH. Near the
  // clustering threshold dH falls below the tolerance (7.8e-5 T at S0 = 3.6 um, k = 0.0104 N/m
  // in Fig. 2.5); a bracket of the tolerance's width there makes dH the bracket's artefact (it
  // came out as 0 or as 0.01 T / 128 from point to point: the ragged column of Fig. 2.5).
  double delta_relative = 1e-2;
  // ... but no bracket narrower than tolerance x finest_fraction (1e-9 T by default; also the
  // finest step of the search for a bistable range inside a sweep step).
  double finest_fraction = 1e-5;
  // Two relaxed states differ if |d_a - d_b| > this * R and by more than 10 times their
  // estimated position errors together (so that the comparison never rests on solver noise).
  double distinct_states = 1e-3;
};

// Finds the bistable range from a sweep's first quadrant (rising branch 0, falling branch 1)
// and refines each end by bisection: at a trial field the pair is relaxed from both branches'
// neighbouring states; if the two relaxed states differ, the field is inside the bistable
// range. This locates the folds to `tolerance`, much finer than the sweep step, and finer
// still where dH is small (delta_relative above). A bistable range narrower than the sweep
// step is searched for inside each step where the rising branch jumps, down to brackets of
// tolerance x finest_fraction while the two ends stay distinct states. Every
// bisection stops when its midpoint can no longer be represented between its ends, so a
// tolerance below double precision ends at the finest bracket the arithmetic allows (reported
// in `uncertainty`).
CriticalFields find_critical_fields(const PairSystem& system, const HysteresisLoop& loop,
                                    const CriticalFieldOptions& options = {});

// Convenience for maps: first-quadrant sweep plus refinement.
CriticalFields critical_fields_of(const PairSystem& system, const SweepOptions& sweep,
                                  const CriticalFieldOptions& options = {});

// Number of halvings that narrow a bracket of width `range` to `tolerance`, limited to what a
// double can resolve (at most 1100: from the largest double down to the smallest).
int bisection_limit(double range, double tolerance);

}  // namespace mresim::pair
