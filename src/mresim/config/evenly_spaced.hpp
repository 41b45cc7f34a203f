#pragma once

#include <vector>

namespace mresim::config {

// The values 0, max/steps, 2 max/steps, ..., max that a run file asks for with `max` and
// `steps` (fields, strains, stresses).
//
// Each value is the double nearest to the 15-significant-digit decimal of i * max / steps, not
// the raw product: 0.025 T in 5 steps and 0.04 T in 8 steps then both give 0.015 T as the
// same double. Without the rounding the first gives 0.015000000000000003 and the second
// 0.015, and a run extended from one plan to the other (`mresim extend`) or two runs compared
// step by step would relax at fields one ulp apart. In a 3D run near a contact instability
// that is enough to end in a neighbouring equilibrium.
//
// Requires steps >= 1 and a finite max; the first value is exactly 0 and the last exactly max.
std::vector<double> evenly_spaced_from_zero(double max, long steps);

}  // namespace mresim::config
