#pragma once

#include "mresim/pair/pair_system.hpp"

namespace mresim::pair {

// Puljiz et al. estimates of the three-spring constants from the polymer shear modulus G,
// the sphere radius R and the zero-field separation S0 (eqs. 2.8, 2.9; M0 = 1/(6 pi G R)).
struct PuljizStiffness {
  double k0 = 0.0;
  double k12 = 0.0;
  // The single-spring constant with the same axial response: k = k0/2 + k12 (Section 2.4).
  double equivalent_single() const { return 0.5 * k0 + k12; }
};
PuljizStiffness puljiz_stiffness(double shear_modulus, double radius, double rest_separation);

// Young's modulus <-> spring constant, treating the polymer between the spheres as a cylinder.
// Chapter 2 (Section 2.4): k = E A / S0 with A = pi R^2.
double spring_from_youngs_chapter2(double youngs_modulus, double radius, double rest_separation);
double youngs_from_spring_chapter2(double k, double radius, double rest_separation);
// Chapter 3 (Section 3.6): E = 2 k S0 / (pi D^2), D = 2R, i.e. half the Chapter 2 value of E
// for the same k (the two chapters' cylinders differ by that factor; both are reproduced).
double spring_from_youngs_chapter3(double youngs_modulus, double radius, double rest_separation);
double youngs_from_spring_chapter3(double k, double radius, double rest_separation);

// Eq. 2.10: the largest S0 at which a saturated pair along the field clusters for spring
// constant k: S0 < (5/4) (6 mu0 Ms^2 V^2 / (pi k))^(1/5).
double clustering_threshold_separation(const SphereMaterial& material, double k);
// Eq. 2.10 solved for k: the largest k at which a pair at S0 clusters.
double clustering_threshold_stiffness(const SphereMaterial& material, double rest_separation);

// Section 2.4: the mean separation of an isotropic MRE, S0_avg = (V / Phi)^(1/3).
double mean_separation(double radius, double volume_fraction);

}  // namespace mresim::pair
