#include "mresim/magnetism/runs/preisach_expectation.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace mresim::magnetism::runs {

namespace {

// P(X >= x) for X ~ N(mean, sd), sd >= 0 (a step function for sd = 0).
double upper_tail(double x, double mean, double sd) {
  if (sd == 0.0) return x <= mean ? 1.0 : 0.0;
  return 0.5 * std::erfc((x - mean) / (sd * std::numbers::sqrt2));
}

// P(beta >= B) = P(a >= B) P(b >= B): the relays still up on the descending branch.
double still_up(const PreisachParameters& p, double b) {
  return upper_tail(b, p.switch_up_mean_t, p.switch_sd_t) *
         upper_tail(b, p.switch_down_mean_t, p.switch_sd_t);
}

}  // namespace

double expected_descending_branch(const PreisachParameters& p, double b_tesla) {
  return 1.0 - 2.0 * still_up(p, b_tesla);
}

double expected_remanence(const PreisachParameters& p) {
  return expected_descending_branch(p, 0.0);
}

double expected_coercive_field(const PreisachParameters& p) {
  // M = 0 where still_up = 1/2. 40 sd beyond the means still_up is 1 resp. 0 in double.
  double lo = std::min(p.switch_up_mean_t, p.switch_down_mean_t) - 40.0 * p.switch_sd_t;
  double hi = std::max(p.switch_up_mean_t, p.switch_down_mean_t) + 40.0 * p.switch_sd_t;
  for (int i = 0; i < 200 && hi - lo > 0.0; ++i) {
    const double mid = 0.5 * (lo + hi);
    if (mid == lo || mid == hi) break;
    (still_up(p, mid) > 0.5 ? lo : hi) = mid;
  }
  return -0.5 * (lo + hi);
}

double expected_up_fraction(const PreisachParameters& p, double b_tesla) {
  // P(a <= B) = 1 - P(a >= B) for a continuous distribution.
  return (1.0 - upper_tail(b_tesla, p.switch_up_mean_t, p.switch_sd_t)) *
         (1.0 - upper_tail(b_tesla, p.switch_down_mean_t, p.switch_sd_t));
}

double clipped_weight_fraction(const PreisachParameters& p) {
  return 1.0 - upper_tail(p.weight_min, p.weight_mean, p.weight_sd);
}

}  // namespace mresim::magnetism::runs
