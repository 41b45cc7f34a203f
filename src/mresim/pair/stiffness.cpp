#include "mresim/pair/stiffness.hpp"

#include <cmath>
#include <numbers>

namespace mresim::pair {

PuljizStiffness puljiz_stiffness(double shear_modulus, double radius, double rest_separation) {
  const double inv_m0 = 6.0 * std::numbers::pi * shear_modulus * radius;  // 1/M0
  const double q = radius / rest_separation;
  PuljizStiffness k;
  k.k0 = inv_m0 * (1.0 - 1.5 * q + 2.25 * q * q - 19.0 / 8.0 * q * q * q +
                   93.0 / 16.0 * q * q * q * q);        // eq. 2.8
  k.k12 = inv_m0 * (1.5 * q + 19.0 / 8.0 * q * q * q);  // eq. 2.9
  return k;
}

double spring_from_youngs_chapter2(double youngs_modulus, double radius, double rest_separation) {
  return youngs_modulus * std::numbers::pi * radius * radius / rest_separation;
}

double youngs_from_spring_chapter2(double k, double radius, double rest_separation) {
  return k * rest_separation / (std::numbers::pi * radius * radius);
}

double spring_from_youngs_chapter3(double youngs_modulus, double radius, double rest_separation) {
  const double diameter = 2.0 * radius;
  return youngs_modulus * std::numbers::pi * diameter * diameter / (2.0 * rest_separation);
}

double youngs_from_spring_chapter3(double k, double radius, double rest_separation) {
  const double diameter = 2.0 * radius;
  return 2.0 * k * rest_separation / (std::numbers::pi * diameter * diameter);
}

namespace {
// 6 mu0 Ms^2 V^2 / pi, the saturated dipole-force constant of eq. 2.10 (times 4).
double saturated_force_constant(const SphereMaterial& m) {
  const double v = m.volume();
  return 6.0 * kMu0 * m.saturation_magnetization * m.saturation_magnetization * v * v /
         std::numbers::pi;
}
}  // namespace

double clustering_threshold_separation(const SphereMaterial& material, double k) {
  return 1.25 * std::pow(saturated_force_constant(material) / k, 0.2);
}

double clustering_threshold_stiffness(const SphereMaterial& material, double rest_separation) {
  return saturated_force_constant(material) / std::pow(rest_separation / 1.25, 5);
}

double mean_separation(double radius, double volume_fraction) {
  const double v = 4.0 / 3.0 * std::numbers::pi * radius * radius * radius;
  return std::cbrt(v / volume_fraction);
}

}  // namespace mresim::pair
