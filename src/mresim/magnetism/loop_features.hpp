#pragma once

// Coercive field B_c and remanence M_r/Ms of a hysteresis loop (dissertation Section 1.3.3,
// Fig. 1.5), read off the descending branch of any sampled MagnetizationCurve.

#include "mresim/magnetism/magnetization_curve.hpp"

namespace mresim::magnetism {

struct LoopFeatures {
  // -B at the first zero crossing of M on the descending branch (positive for a normal
  // hysteresis loop, 0 for an anhysteretic curve).
  double coercive_field_t;
  // M/Ms where the descending branch first reaches B = 0.
  double remanence;
};

// Both values are linear interpolations between consecutive samples of the descending branch
// (branch == kBranchDown); the segment from the last point before that branch (the turning
// point) into it is included. A crossing counts from a sample with value > 0 to the next with
// value <= 0. Throws std::invalid_argument if the vectors differ in length, or if the
// descending branch never crosses B = 0 or M = 0.
LoopFeatures loop_features(const MagnetizationCurve& curve);

}  // namespace mresim::magnetism
