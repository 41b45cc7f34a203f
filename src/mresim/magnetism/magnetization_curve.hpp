#pragma once

// Magnetization curves M/Ms(B) sampled along a field sweep, shared by the anhysteretic
// (Froehlich-Kennelly, eq. 1.5) and hysteretic (Preisach, Fig. 1.5) response models of
// dissertation Section 1.3.3.

#include <vector>

namespace mresim::magnetism {

// Branch indices of the major-loop sweep 0 -> +b_max -> -b_max -> +b_max, numbered like the
// legs of Fig. 1.5 (there 1, 2, 3; here 0-based).
inline constexpr int kBranchInitialUp = 0;  // 0 -> +b_max (initial magnetization curve)
inline constexpr int kBranchDown = 1;       // +b_max -> -b_max (descending leg)
inline constexpr int kBranchUp = 2;         // -b_max -> +b_max (final ascending leg)

// One sampled curve: the applied field B = mu0 H in tesla, the normalized magnetization M/Ms
// and the branch index of each sample. All three vectors have the same length.
struct MagnetizationCurve {
  std::vector<double> b_tesla;
  std::vector<double> m_over_ms;
  std::vector<int> branch;
};

// One applied field value of a sweep and the branch it belongs to.
struct SweepPoint {
  double b_tesla;
  int branch;
};

// The field values of the major-loop sweep 0 -> +b_max -> -b_max -> +b_max.
// The grid is B_k = k * b_max / n with n = ceil(b_max / b_step), so the turning points and
// B = 0 are hit exactly, the loop is exactly symmetric and the actual step is <= b_step.
// Every field value is applied once: a turning point belongs to the branch that reaches it
// (branch 0 holds 0..+b_max, branch 1 the 2n points below +b_max down to -b_max, branch 2 the
// 2n points above -b_max up to +b_max), 5n + 1 points in all.
// Throws std::invalid_argument unless 0 < b_step and 0 < b_max are finite and the sweep has
// fewer than 10^8 points per branch.
std::vector<SweepPoint> major_loop_sweep(double b_max, double b_step);

}  // namespace mresim::magnetism
