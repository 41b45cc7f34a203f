#include "mresim/mess/terms/spring_rows.hpp"

#include <cmath>

#include "mresim/mess/terms/simd_clones.hpp"

namespace mresim::mess::spring_rows {

MRESIM_SIMD_CLONES
void tensions(std::int64_t count, Components first, Components second,
              const std::uint8_t* stiffness_index, const double* stiffness_table,
              double rest_length, double* tension, double* energy, double* rounding) {
#pragma omp simd
  for (std::int64_t i = 0; i < count; ++i) {
    const double rx = second.x[i] - first.x[i];
    const double ry = second.y[i] - first.y[i];
    const double rz = second.z[i] - first.z[i];
    const double l = std::sqrt((rx * rx + ry * ry) + rz * rz);
    const double stretch = l - rest_length;
    const double k_stretch = stiffness_table[stiffness_index[i]] * stretch;
    tension[i] = k_stretch / l;
    energy[i] = 0.5 * k_stretch * stretch;
    rounding[i] = std::abs(k_stretch) * l;
  }
}

MRESIM_SIMD_CLONES
void add_backward(std::int64_t count, const double* tension, Components first, Components second,
                  double* gx, double* gy, double* gz) {
#pragma omp simd
  for (std::int64_t i = 0; i < count; ++i) {
    gx[i] += tension[i] * (second.x[i] - first.x[i]);
    gy[i] += tension[i] * (second.y[i] - first.y[i]);
    gz[i] += tension[i] * (second.z[i] - first.z[i]);
  }
}

MRESIM_SIMD_CLONES
void subtract_forward(std::int64_t count, const double* tension, Components first,
                      Components second, double* gx, double* gy, double* gz) {
#pragma omp simd
  for (std::int64_t i = 0; i < count; ++i) {
    gx[i] -= tension[i] * (second.x[i] - first.x[i]);
    gy[i] -= tension[i] * (second.y[i] - first.y[i]);
    gz[i] -= tension[i] * (second.z[i] - first.z[i]);
  }
}

}  // namespace mresim::mess::spring_rows
