#pragma once

// The dissertation's reference values that tests of several models compare against: its
// particles and its polymer lattice.

namespace mresim::testing {

inline constexpr double kR = 1.5e-6;  // particle radius R (m)
inline constexpr double kMs = 1.6e6;  // particles' saturation magnetization Ms (A/m)

inline constexpr double kE = 9.0e3;           // polymer's Young's modulus E (Pa)
inline constexpr double kLe = 3.0e-6 / 11.0;  // element length l_e = 2R / 11 at n_d = 5 (m)

}  // namespace mresim::testing
