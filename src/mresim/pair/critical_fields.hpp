#pragma once

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
  double uncertainty = 0.0;  // half-width of the final bracket, T
  double delta() const { return hysteresis ? hc2 - hc1 : 0.0; }
};

struct CriticalFieldOptions {
  double tolerance = 1e-4;        // T, width of the final bracket
  double distinct_states = 1e-3;  // two relaxed states differ if |d_a - d_b| > this * R
};

// Finds the bistable range from a sweep's first quadrant (rising branch 0, falling branch 1)
// and refines each end by bisection: at a trial field the pair is relaxed from both branches'
// neighbouring states; if the two relaxed states differ, the field is inside the bistable
// range. This locates the folds to `tolerance`, much finer than the sweep step.
CriticalFields find_critical_fields(const PairSystem& system, const HysteresisLoop& loop,
                                    const CriticalFieldOptions& options = {});

// Convenience for maps: first-quadrant sweep plus refinement.
CriticalFields critical_fields_of(const PairSystem& system, const SweepOptions& sweep,
                                  const CriticalFieldOptions& options = {});

}  // namespace mresim::pair
