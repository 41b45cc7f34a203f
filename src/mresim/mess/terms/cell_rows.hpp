#pragma once

// The volume terms over a row of cells, one SIMD lane per cell: a run of cells consecutive along
// one axis (z in the single-process kernel, VolumeKernel, and in the distributed one), whose
// vertex positions come from node component arrays in which that axis runs fastest, so that
// each vertex of the run is a contiguous load. Each
// lane does the scalar operations of elastic::cell_value and elastic::vertex_gradient in the
// same order, without fused multiply-adds (simd_clones.hpp): the results are bitwise those of
// the scalar kernel.

#include <array>
#include <cstdint>

namespace mresim::mess::cell_rows {

// The run's eight vertices, local vertex v = 2 dx + 4 dy + dz (lattice::vertex_offset), each
// as three component arrays starting at the run's first cell.
struct Corners {
  std::array<const double*, 8> x;
  std::array<const double*, 8> y;
  std::array<const double*, 8> z;
};

// The nine gradient coefficient arrays of a run (elastic::cell_value's t[0..8]), each starting
// at the run's first cell.
template <class Pointer>
using Coefficients = std::array<Pointer, 9>;

// For each of the run's `count` cells: its coefficients t (f (b x c), f (c x a), f (a x b),
// f = force_factor kappa (V/V0 - 1)/4, eqs. 4.45-4.48 and 4.66-4.69), its energy
// 1/2 kappa V0 (V/V0 - 1)^2 (eq. 4.64 x V0) and rounding scale |kappa V0 (V/V0 - 1)|.
void coefficients(std::int64_t count, const Corners& corners, double kappa, double v0,
                  double force_factor, const Coefficients<double*>& t, double* energy,
                  double* rounding);

// g += s_a t[0..2] + s_b t[3..5] + s_c t[6..8] (elastic::vertex_gradient) for a run of nodes
// that are the same local vertex, with signs (s_a, s_b, s_c), of a run of cells.
void add_vertex_gradient(std::int64_t count, const Coefficients<const double*>& t, double sa,
                         double sb, double sc, double* gx, double* gy, double* gz);

}  // namespace mresim::mess::cell_rows
