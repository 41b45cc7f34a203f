#pragma once

// Spring constants and the extra bulk modulus of the hybrid mass-spring lattice (Section 4.2.1).
//
// Per cubic cell of edge l_e the lattice carries, after sharing between neighbouring cells,
// 3 edge springs (k_e, length l_e), 6 face diagonals (k_f, sqrt(2) l_e) and 4 body diagonals
// (k_c, sqrt(3) l_e), plus the volume energy 0.5 kappa (V/V0 - 1)^2 per unit volume (eq. 4.16).
// Its small-strain stiffness tensor (eqs. 4.34, 4.37, 4.18) is
//   C_1111 = (k_e + 4/3 k_c + 2 k_f)/l_e + kappa,
//   C_1122 = (4/3 k_c + k_f)/l_e + kappa,      C_1212 = (4/3 k_c + k_f)/l_e.
// It is isotropic iff k_e = 8/3 k_c + k_f (eq. 4.40); then G = (4/3 k_c + k_f)/l_e (eq. 4.41)
// and lambda = G + kappa, so kappa = lambda - G = E (4 nu - 1)/(2 (1+nu)(1-2 nu)) (eq. 4.22).
// With A = k_f/k_c:  k_c = 3 G l_e/(4+3A),  k_f = A k_c,  k_e = G l_e (8+3A)/(4+3A).
//
// The two profiles differ only in the G put into those three formulas:
//  - physical: G = E/(2(1+nu)), so a particle-free block has exactly the user's E and nu;
//  - seed:     G = 2E/5 (the nu = 1/4 "rari" relation, eq. 4.14), which is what eqs. 4.42-4.44
//              and the original code use for every nu: k_c = (6/5) E l_e/(4+3A),
//              k_e = (2/5) E l_e (8+3A)/(4+3A) (eq. 4.44 with its extra 1/(4+3A) removed).
// kappa is eq. 4.22 in both profiles. See docs/lattice.md for the consequences.

#include <string>
#include <string_view>

namespace mresim::lattice {

// Which shear modulus the springs are given (the model profile decides:
// mess/profile/model_profile.hpp).
enum class ShearModulusRule {
  from_youngs_and_poisson,  // G = E/(2(1+nu)): a particle-free lattice has the given E and nu
  two_fifths_youngs,        // G = 2E/5 whatever nu (eq. 4.14, as eqs. 4.42-4.44 use it)
};

// Spring constants in N/m: edge (k_e), face diagonal (k_f), body (centre) diagonal (k_c).
struct SpringConstants {
  double edge = 0.0;
  double face = 0.0;
  double body = 0.0;
};

// Everything the elastic energy terms need for one material.
struct LatticeStiffness {
  SpringConstants springs;  // N/m
  double kappa = 0.0;       // extra bulk modulus, Pa (eq. 4.22)
};

// Iron's Young's modulus (Section 4.2.2, docs/original-code.md#constants).
inline constexpr double kIronYoungsModulus = 2.11e11;
// Particle springs are this many times stiffer than polymer ones unless iron is softer.
inline constexpr double kParticleStiffnessFactor = 1.0e4;

// Throws std::invalid_argument unless -1 < nu < 1/2 (strictly: nu = 1/2 makes kappa infinite,
// nu = -1 makes the bulk modulus vanish). The message names the value and the allowed range.
void validate_poisson_ratio(double poisson_ratio);
// Throws std::invalid_argument unless E > 0 and finite.
void validate_youngs_modulus(double youngs_modulus);
// Throws std::invalid_argument unless A = k_f/k_c >= 0 and finite.
void validate_stiffness_ratio(double stiffness_ratio);

// kappa >= 0 iff nu >= 1/4 (both profiles). For nu < 1/4 the volume term is an energy *gain*
// per unit volume change; the lattice stays stable as long as its bulk modulus
// K = kappa + 5G/3 (eq. 4.21) is positive: always for the physical profile (K = E/(3(1-2nu))),
// only for nu > seed_bulk_stability_limit() in the seed profile (K = kappa + 2E/3 there).
bool kappa_nonnegative(double poisson_ratio);
// (1 - sqrt(3/2))/2 = -0.1124: below it the seed profile's bulk modulus is negative.
double seed_bulk_stability_limit();

// G = E/(2(1+nu)) or 2E/5 by the rule.
double target_shear_modulus(ShearModulusRule rule, double youngs_modulus, double poisson_ratio);

// Spring constants with shear modulus G on a lattice of edge l_e (eqs. 4.40-4.43 solved for
// the k's): k_c = 3 G l_e/(4+3A), k_f = A k_c, k_e = G l_e (8+3A)/(4+3A).
SpringConstants spring_constants_for_shear_modulus(double shear_modulus, double element_length,
                                                   double stiffness_ratio = 1.0);

// Eq. 4.95: k_eff = 2 k_e + 8 k_f/sqrt(2) + 4 k_c, the stiffness scale of one interior polymer
// node (time unit t_c, eq. 4.94, and the solvers' force unit k_eff l_e).
double effective_spring_constant(const SpringConstants& springs);

// eq. 4.22, kappa = E (4 nu - 1)/(2 (1+nu)(1-2nu)); the same in both profiles.
double extra_bulk_modulus(double youngs_modulus, double poisson_ratio);

// The polymer's constants under the rule. Validates E, nu and A (std::invalid_argument).
LatticeStiffness polymer_stiffness(ShearModulusRule rule, double youngs_modulus,
                                   double poisson_ratio, double element_length,
                                   double stiffness_ratio = 1.0);

// E_p = min(2.11e11 Pa, 1e4 E) (Section 4.2.2).
double particle_youngs_modulus(double youngs_modulus);
// Spring constants joining two nodes of one particle: the rule's formulas with E_p instead
// of E (and the polymer's nu), i.e. exactly 1e4 times the polymer's while 1e4 E < 2.11e11 Pa.
SpringConstants particle_spring_constants(ShearModulusRule rule, double youngs_modulus,
                                          double poisson_ratio, double element_length,
                                          double stiffness_ratio = 1.0);

// Small-strain moduli of an infinite (or affinely deformed) lattice with these constants.
struct LatticeModuli {
  double c1111 = 0.0;             // Pa, uniaxial-strain modulus lambda + 2G
  double c1122 = 0.0;             // Pa, lambda
  double shear_modulus = 0.0;     // C_1212 (eq. 4.41), Pa
  double bulk_modulus = 0.0;      // (C_1111 + 2 C_1122)/3 (eq. 4.21 when isotropic), Pa
  double youngs_modulus = 0.0;    // uniaxial stress, Pa (eq. 4.20 when isotropic)
  double poisson_ratio = 0.0;     // uniaxial stress (eq. 4.20 when isotropic)
  double cubic_anisotropy = 0.0;  // C_1111 - C_1122 - 2 C_1212; zero iff isotropic (4.39)
};
LatticeModuli lattice_moduli(const LatticeStiffness& stiffness, double element_length);

}  // namespace mresim::lattice
