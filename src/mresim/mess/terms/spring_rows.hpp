#pragma once

// The spring formulas over a row of the grid, one lane per node: the springs of one forward
// offset for a run of consecutive nodes along z (node index = iz + nz (ix + nx iy)), whose
// positions are in three separate arrays (x, y and z components), so that the compiler runs
// them in SIMD registers. Each lane does the scalar operations of elastic::spring_value and of
// the per-node gather in elastic_terms.cpp in the same order, with no fused multiply-adds
// (the build is ISO C++, which keeps -ffp-contract off), and square roots and divisions are
// correctly rounded in SIMD as in scalar code: the results are bitwise those of the scalar
// kernel. On x86-64 the functions are compiled for AVX-512, AVX2 and the baseline, and the
// loader picks the widest the processor has.

#include <cstdint>

namespace mresim::mess::spring_rows {

// Three component arrays, each already offset to the run's first node.
struct Components {
  const double* x;
  const double* y;
  const double* z;
};

// The run's `count` springs from `first` to `second`: with r = second - first,
// l = sqrt((r_x^2 + r_y^2) + r_z^2) (what Eigen's Vector3d::norm gives), stiffness
// k = stiffness_table[stiffness_index[i]] and rest length L:
//   tension[i] = k (l - L) / l, energy[i] = 1/2 k (l - L) (l - L), rounding[i] = |k (l - L)| l
// (elastic::spring_value, eqs. 4.62-4.63).
void tensions(std::int64_t count, Components first, Components second,
              const std::uint8_t* stiffness_index, const double* stiffness_table,
              double rest_length, double* tension, double* energy, double* rounding);

// g += tension[i] (second - first) (the springs that end at the run's nodes).
void add_backward(std::int64_t count, const double* tension, Components first, Components second,
                  double* gx, double* gy, double* gz);

// g -= tension[i] (second - first) (the springs that start at the run's nodes).
void subtract_forward(std::int64_t count, const double* tension, Components first,
                      Components second, double* gx, double* gy, double* gz);

}  // namespace mresim::mess::spring_rows
