#pragma once

#include <numbers>

namespace mresim {

// Vacuum permeability in T m / A (SI, the value the dissertation uses: 4 pi 1e-7).
inline constexpr double kMu0 = 4.0e-7 * std::numbers::pi;

// Applied fields are given as B = mu0 H in tesla (the dissertation's axes); internally the
// two-dipole model works in the reduced field h = H / Ms (Section 2.4).
inline double reduced_field(double b_tesla, double saturation_magnetization) {
  return b_tesla / (kMu0 * saturation_magnetization);
}

}  // namespace mresim
