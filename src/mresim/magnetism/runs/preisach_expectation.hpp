#pragma once

// Large-population (expected) shape of the Preisach major loop of Fig. 1.5, for `mresim info`
// and as a check on the simulated loop.
//
// Each relay draws a ~ N(switch_up_mean, sd) and b ~ N(switch_down_mean, sd) and keeps
// alpha = max(a, b), beta = min(a, b) (preisach.hpp). Coming down from positive saturation, a
// relay is still up at field B iff B > beta, and P(beta >= B) = P(a >= B) P(b >= B). The
// weights are drawn independently of the switching fields, so in expectation
//   M/Ms(B) = 1 - 2 P(a >= B) P(b >= B)              (descending branch)
// whatever the weight distribution; the sampling noise is of order 1/sqrt(relays).

#include "mresim/magnetism/preisach.hpp"

namespace mresim::magnetism::runs {

// Expected M/Ms on the descending branch from positive saturation (formula above).
double expected_descending_branch(const PreisachParameters& p, double b_tesla);

// Expected remanence: expected_descending_branch at B = 0.
double expected_remanence(const PreisachParameters& p);

// Expected coercive field B_c > 0: minus the zero of expected_descending_branch, by bisection
// (the branch decreases monotonically from 1 to -1). Without the swap it would be
// -switch_down_mean; with the Fig. 1.5 parameters it is 0.35006 T.
double expected_coercive_field(const PreisachParameters& p);

// Expected fraction of the relays switched up once the field has reached B:
// P(alpha <= B) = P(a <= B) P(b <= B). Near 1 at field.max means the loop starts from
// saturation, which the two expectations above assume.
double expected_up_fraction(const PreisachParameters& p, double b_tesla);

// Fraction of the weight draws N(weight_mean, weight_sd) that fall below weight_min and are
// clipped up to it.
double clipped_weight_fraction(const PreisachParameters& p);

}  // namespace mresim::magnetism::runs
