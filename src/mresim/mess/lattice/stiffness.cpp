#include "mresim/mess/lattice/stiffness.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace mresim::lattice {

void validate_poisson_ratio(double poisson_ratio) {
  if (!(poisson_ratio > -1.0 && poisson_ratio < 0.5)) {
    throw std::invalid_argument(
        fmt::format("poisson_ratio = {} is outside the allowed open interval (-1, 0.5) (at 0.5 "
                    "the extra bulk modulus of eq. 4.22 is infinite, at -1 the bulk modulus "
                    "vanishes)",
                    poisson_ratio));
  }
}

void validate_youngs_modulus(double youngs_modulus) {
  if (!(youngs_modulus > 0.0) || !std::isfinite(youngs_modulus)) {
    throw std::invalid_argument(fmt::format(
        "youngs_modulus = {} Pa is not allowed: it must be positive and finite", youngs_modulus));
  }
}

void validate_stiffness_ratio(double stiffness_ratio) {
  if (!(stiffness_ratio >= 0.0) || !std::isfinite(stiffness_ratio)) {
    throw std::invalid_argument(
        fmt::format("stiffness ratio A = k_f/k_c = {} is not allowed: it must be >= 0 and finite",
                    stiffness_ratio));
  }
}

bool kappa_nonnegative(double poisson_ratio) { return poisson_ratio >= 0.25; }

double seed_bulk_stability_limit() {
  // Seed: K = kappa + 5/3 (2E/5) = kappa + 2E/3 = 0  <=>  8 nu^2 - 8 nu - 1 = 0.
  return 0.5 * (1.0 - std::sqrt(1.5));
}

double target_shear_modulus(ShearModulusRule rule, double youngs_modulus, double poisson_ratio) {
  if (rule == ShearModulusRule::two_fifths_youngs)
    return 0.4 * youngs_modulus;  // eq. 4.14: E = 5G/2
  return youngs_modulus / (2.0 * (1.0 + poisson_ratio));
}

SpringConstants spring_constants_for_shear_modulus(double shear_modulus, double element_length,
                                                   double stiffness_ratio) {
  const double a = stiffness_ratio;
  SpringConstants k;
  // eq. 4.41: G l_e = (4/3 + A) k_c.
  k.body = 3.0 * shear_modulus * element_length / (4.0 + 3.0 * a);
  k.face = a * k.body;  // eq. 4.43
  // eq. 4.40: k_e = (8/3 + A) k_c = G l_e (8+3A)/(4+3A).
  k.edge = shear_modulus * element_length * (8.0 + 3.0 * a) / (4.0 + 3.0 * a);
  return k;
}

double effective_spring_constant(const SpringConstants& springs) {
  return 2.0 * springs.edge + 8.0 * springs.face / std::numbers::sqrt2 + 4.0 * springs.body;
}

double extra_bulk_modulus(double youngs_modulus, double poisson_ratio) {
  // eq. 4.22 (= lambda - G for G = E/(2(1+nu))).
  return youngs_modulus * (4.0 * poisson_ratio - 1.0) /
         (2.0 * (1.0 + poisson_ratio) * (1.0 - 2.0 * poisson_ratio));
}

LatticeStiffness polymer_stiffness(ShearModulusRule rule, double youngs_modulus,
                                   double poisson_ratio, double element_length,
                                   double stiffness_ratio) {
  validate_youngs_modulus(youngs_modulus);
  validate_poisson_ratio(poisson_ratio);
  validate_stiffness_ratio(stiffness_ratio);
  LatticeStiffness s;
  s.springs = spring_constants_for_shear_modulus(
      target_shear_modulus(rule, youngs_modulus, poisson_ratio), element_length, stiffness_ratio);
  s.kappa = extra_bulk_modulus(youngs_modulus, poisson_ratio);
  return s;
}

double particle_youngs_modulus(double youngs_modulus) {
  return std::min(kIronYoungsModulus, kParticleStiffnessFactor * youngs_modulus);
}

SpringConstants particle_spring_constants(ShearModulusRule rule, double youngs_modulus,
                                          double poisson_ratio, double element_length,
                                          double stiffness_ratio) {
  return polymer_stiffness(rule, particle_youngs_modulus(youngs_modulus), poisson_ratio,
                           element_length, stiffness_ratio)
      .springs;
}

LatticeModuli lattice_moduli(const LatticeStiffness& stiffness, double element_length) {
  const SpringConstants& k = stiffness.springs;
  LatticeModuli m;
  m.c1111 = (k.edge + 4.0 / 3.0 * k.body + 2.0 * k.face) / element_length + stiffness.kappa;
  m.shear_modulus = (4.0 / 3.0 * k.body + k.face) / element_length;  // eqs. 4.37, 4.41
  m.c1122 = m.shear_modulus + stiffness.kappa;                       // eq. 4.18
  m.bulk_modulus = (m.c1111 + 2.0 * m.c1122) / 3.0;
  // Uniaxial stress along a cube axis of a cubic medium.
  m.youngs_modulus = (m.c1111 - m.c1122) * (m.c1111 + 2.0 * m.c1122) / (m.c1111 + m.c1122);
  m.poisson_ratio = m.c1122 / (m.c1111 + m.c1122);
  m.cubic_anisotropy = m.c1111 - m.c1122 - 2.0 * m.shear_modulus;
  return m;
}

}  // namespace mresim::lattice
