#pragma once

// Material of the identical, magnetically soft spheres of the 3D model (Chapter 4): radius,
// initial susceptibility chi0 and saturation magnetization Ms of the Froehlich-Kennelly law
// (eq. 4.55). The dissertation's figures use R = 1.5 um, chi0 = 70, Ms = 1.6e6 A/m.

#include <cmath>
#include <numbers>
#include <stdexcept>

namespace mresim::magnetism {

struct MagneticParticles {
  double radius = 1.5e-6;  // m
  double chi0 = 70.0;      // initial susceptibility (dimensionless, SI)
  double Ms = 1.6e6;       // A/m

  // Sphere volume V = 4 pi R^3 / 3 (m^3); the moment is m = V M.
  double volume() const { return 4.0 / 3.0 * std::numbers::pi * radius * radius * radius; }

  // Throws std::invalid_argument naming the offending quantity.
  void validate() const {
    if (!(std::isfinite(radius) && radius > 0.0)) {
      throw std::invalid_argument("MagneticParticles: radius must be finite and > 0");
    }
    if (!(std::isfinite(chi0) && chi0 > 0.0)) {
      throw std::invalid_argument("MagneticParticles: chi0 must be finite and > 0");
    }
    if (!(std::isfinite(Ms) && Ms > 0.0)) {
      throw std::invalid_argument("MagneticParticles: Ms must be finite and > 0");
    }
  }
};

}  // namespace mresim::magnetism
