#pragma once

// The per-spring and per-cell formulas of the elastic terms, shared by the single-process
// kernels (elastic_terms.cpp) and the distributed ones (distributed/distributed_elastic.cpp),
// so that both do the same floating-point operations and give bitwise the same gradients.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cmath>

#include "mresim/mess/lattice/springs.hpp"
#include "mresim/mess/lattice/volume_elements.hpp"

namespace mresim::mess::elastic {

// Rest length of each spring kind, element_length x rest_length_factor (what
// SpringSet::rest_length gives), indexed by SpringKind.
inline std::array<double, 3> rest_lengths(double element_length) {
  std::array<double, 3> lengths{};
  for (const auto kind :
       {lattice::SpringKind::edge, lattice::SpringKind::face, lattice::SpringKind::body}) {
    lengths[static_cast<std::size_t>(kind)] = element_length * lattice::rest_length_factor(kind);
  }
  return lengths;
}

// One spring of stiffness k and rest length L whose ends are l apart: its tension
// k (l - L)/l, so that the gradient on its second end is tension x r (eq. 4.63, r = x_j - x_i);
// its energy 1/2 k (l - L)^2 (eq. 4.62) and that energy's rounding scale |k (l - L)| l.
struct SpringValue {
  double tension = 0.0;
  double energy = 0.0;
  double rounding = 0.0;
};

inline SpringValue spring_value(double k, double rest_length, double l) {
  const double stretch = l - rest_length;
  const double k_stretch = k * stretch;
  return {k * stretch / l, 0.5 * k_stretch * stretch, std::abs(k_stretch) * l};
}

// One cell, eq. 4.64 x V0 with V = a . (b x c) (eq. 4.48): its energy 1/2 kappa V0 (V/V0 - 1)^2
// and rounding scale |kappa V0 (V/V0 - 1)|. If `t` is not null, the cell's gradient coefficients
// t[0..2] = f (b x c), t[3..5] = f (c x a), t[6..8] = f (a x b), f = force_factor kappa
// (V/V0 - 1)/4, so that dU/dx_v = s_a f (b x c) + s_b f (c x a) + s_c f (a x b) (eqs.
// 4.66-4.69 with the 1/4 of the averaged edge vectors; vertex_gradient).
struct CellValue {
  double energy = 0.0;
  double rounding = 0.0;
};

inline CellValue cell_value(const lattice::CellVertices& x, double kappa, double v0,
                            double force_factor, double* t) {
  const lattice::EdgeVectors e = lattice::averaged_edge_vectors(x);
  const Eigen::Vector3d bxc = e.b.cross(e.c);
  const double dv = e.a.dot(bxc) / v0 - 1.0;
  if (t != nullptr) {
    const double f = 0.25 * force_factor * kappa * dv;
    Eigen::Map<Eigen::Vector3d> t_bc(t);
    Eigen::Map<Eigen::Vector3d> t_ca(t + 3);
    Eigen::Map<Eigen::Vector3d> t_ab(t + 6);
    t_bc = f * bxc;
    t_ca = f * e.c.cross(e.a);
    t_ab = f * e.a.cross(e.b);
  }
  return {0.5 * kappa * v0 * dv * dv, std::abs(kappa * v0 * dv)};
}

// The gradient at local vertex v (lattice::vertex_offset) of a cell with coefficients t.
inline Eigen::Vector3d vertex_gradient(const double* t, int v) {
  const double sa = (v & 2) ? 1.0 : -1.0;
  const double sb = (v & 4) ? 1.0 : -1.0;
  const double sc = (v & 1) ? 1.0 : -1.0;
  return sa * Eigen::Map<const Eigen::Vector3d>(t) + sb * Eigen::Map<const Eigen::Vector3d>(t + 3) +
         sc * Eigen::Map<const Eigen::Vector3d>(t + 6);
}

}  // namespace mresim::mess::elastic
