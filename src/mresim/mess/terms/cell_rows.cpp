#include "mresim/mess/terms/cell_rows.hpp"

#include <cmath>

#include "mresim/mess/terms/simd_clones.hpp"

namespace mresim::mess::cell_rows {

MRESIM_SIMD_CLONES
void coefficients(std::int64_t count, const Corners& corners, double kappa, double v0,
                  double force_factor, const Coefficients<double*>& t, double* energy,
                  double* rounding) {
  const std::array<const double*, 8> px = corners.x;
  const std::array<const double*, 8> py = corners.y;
  const std::array<const double*, 8> pz = corners.z;
  const Coefficients<double*> out = t;
  // The averaged edge vectors a, b, c (eqs. 4.45-4.47), component by component, summed in the
  // order lattice::averaged_edge_vectors writes them.
  const auto edge_a = [](const std::array<const double*, 8>& p, std::int64_t i) {
    return 0.25 * (p[2][i] - p[0][i] + p[3][i] - p[1][i] + p[6][i] - p[4][i] + p[7][i] - p[5][i]);
  };
  const auto edge_b = [](const std::array<const double*, 8>& p, std::int64_t i) {
    return 0.25 * (p[4][i] - p[0][i] + p[6][i] - p[2][i] + p[5][i] - p[1][i] + p[7][i] - p[3][i]);
  };
  const auto edge_c = [](const std::array<const double*, 8>& p, std::int64_t i) {
    return 0.25 * (p[1][i] - p[0][i] + p[3][i] - p[2][i] + p[5][i] - p[4][i] + p[7][i] - p[6][i]);
  };
#pragma omp simd
  for (std::int64_t i = 0; i < count; ++i) {
    const double ax = edge_a(px, i);
    const double ay = edge_a(py, i);
    const double az = edge_a(pz, i);
    const double bx = edge_b(px, i);
    const double by = edge_b(py, i);
    const double bz = edge_b(pz, i);
    const double cx = edge_c(px, i);
    const double cy = edge_c(py, i);
    const double cz = edge_c(pz, i);
    // b x c, c x a, a x b as Eigen's cross product forms them.
    const double bc_x = by * cz - bz * cy;
    const double bc_y = bz * cx - bx * cz;
    const double bc_z = bx * cy - by * cx;
    const double dv = (ax * bc_x + ay * bc_y + az * bc_z) / v0 - 1.0;  // V/V0 - 1, eq. 4.48
    const double f = 0.25 * force_factor * kappa * dv;
    out[0][i] = f * bc_x;
    out[1][i] = f * bc_y;
    out[2][i] = f * bc_z;
    out[3][i] = f * (cy * az - cz * ay);
    out[4][i] = f * (cz * ax - cx * az);
    out[5][i] = f * (cx * ay - cy * ax);
    out[6][i] = f * (ay * bz - az * by);
    out[7][i] = f * (az * bx - ax * bz);
    out[8][i] = f * (ax * by - ay * bx);
    energy[i] = 0.5 * kappa * v0 * dv * dv;
    rounding[i] = std::abs(kappa * v0 * dv);
  }
}

MRESIM_SIMD_CLONES
void add_vertex_gradient(std::int64_t count, const Coefficients<const double*>& t, double sa,
                         double sb, double sc, double* gx, double* gy, double* gz) {
  const Coefficients<const double*> c = t;
#pragma omp simd
  for (std::int64_t i = 0; i < count; ++i) {
    gx[i] += sa * c[0][i] + sb * c[3][i] + sc * c[6][i];
    gy[i] += sa * c[1][i] + sb * c[4][i] + sc * c[7][i];
    gz[i] += sa * c[2][i] + sb * c[5][i] + sc * c[8][i];
  }
}

}  // namespace mresim::mess::cell_rows
