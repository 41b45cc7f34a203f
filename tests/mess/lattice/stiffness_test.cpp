#include "mresim/mess/lattice/stiffness.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>

#include "../../support/dissertation_values.hpp"
#include "affine_energy.hpp"

namespace mresim::lattice {
namespace {

using mresim::testing::kE;
using mresim::testing::kLe;

constexpr double kNu = 0.47;

// docs/original-code.md#lengths-spring-constants-and-scaling: the original code's constants (A =
// 1): k_e = 22/35 E l_e, k_c = k_f = 6/35 E l_e, independent of nu.
TEST(LatticeStiffness, SeedProfileIsTheOriginalCode) {
  for (const double nu : {0.3, 0.47, 0.49}) {
    const LatticeStiffness s = polymer_stiffness(ShearModulusRule::two_fifths_youngs, kE, nu, kLe);
    EXPECT_NEAR(s.springs.edge, 22.0 / 35.0 * kE * kLe, 1e-15 * kE * kLe);
    EXPECT_NEAR(s.springs.body, 6.0 / 35.0 * kE * kLe, 1e-15 * kE * kLe);
    EXPECT_NEAR(s.springs.face, 6.0 / 35.0 * kE * kLe, 1e-15 * kE * kLe);
    EXPECT_NEAR(s.kappa, kE * (4 * nu - 1) / (2 * (1 + nu) * (1 - 2 * nu)), 1e-9 * kE);
  }
  // General A: eqs. 4.42, 4.43 and 4.44 without its extra 1/(4+3A)
  // (docs/original-code.md#misprints-in-the-dissertation).
  const double a = 2.5;
  const LatticeStiffness s =
      polymer_stiffness(ShearModulusRule::two_fifths_youngs, kE, kNu, kLe, a);
  EXPECT_NEAR(s.springs.body, 1.2 * kE * kLe / (4 + 3 * a), 1e-15 * kE * kLe);
  EXPECT_NEAR(s.springs.face, a * 1.2 * kE * kLe / (4 + 3 * a), 1e-15 * kE * kLe);
  EXPECT_NEAR(s.springs.edge, 0.4 * kE * kLe * (8 + 3 * a) / (4 + 3 * a), 1e-15 * kE * kLe);
}

// The isotropy condition (eq. 4.40) holds in both profiles and any A.
TEST(LatticeStiffness, BothProfilesSatisfyTheIsotropyCondition) {
  for (const ShearModulusRule p :
       {ShearModulusRule::from_youngs_and_poisson, ShearModulusRule::two_fifths_youngs}) {
    for (const double a : {0.0, 0.5, 1.0, 3.0}) {
      const LatticeStiffness s = polymer_stiffness(p, kE, kNu, kLe, a);
      EXPECT_NEAR(s.springs.edge, 8.0 / 3.0 * s.springs.body + s.springs.face,
                  1e-14 * s.springs.edge);
      EXPECT_NEAR(lattice_moduli(s, kLe).cubic_anisotropy, 0.0, 1e-9 * kE);
    }
  }
}

// Physical profile: the lattice moduli are exactly the user's E and nu, G = E/(2(1+nu)),
// K = E/(3(1-2nu)); the seed profile shears with 0.4 E for every nu (3600 Pa for E = 9 kPa).
TEST(LatticeStiffness, LatticeModuliOfBothProfiles) {
  for (const double nu : {-0.5, 0.0, 0.25, 0.3, 0.47, 0.499}) {
    const LatticeModuli m = lattice_moduli(
        polymer_stiffness(ShearModulusRule::from_youngs_and_poisson, kE, nu, kLe), kLe);
    EXPECT_NEAR(m.youngs_modulus, kE, 1e-9 * kE) << nu;
    EXPECT_NEAR(m.poisson_ratio, nu, 1e-12) << nu;
    EXPECT_NEAR(m.shear_modulus, kE / (2 * (1 + nu)), 1e-9 * kE) << nu;
    EXPECT_NEAR(m.bulk_modulus, kE / (3 * (1 - 2 * nu)), 1e-9 * kE / (1 - 2 * nu)) << nu;
    const LatticeModuli seed =
        lattice_moduli(polymer_stiffness(ShearModulusRule::two_fifths_youngs, kE, nu, kLe), kLe);
    EXPECT_NEAR(seed.shear_modulus, 0.4 * kE, 1e-9 * kE) << nu;
  }
  // At nu = 1/4 the two profiles coincide (E = 5G/2, kappa = 0).
  const LatticeStiffness p =
      polymer_stiffness(ShearModulusRule::from_youngs_and_poisson, kE, 0.25, kLe);
  const LatticeStiffness s = polymer_stiffness(ShearModulusRule::two_fifths_youngs, kE, 0.25, kLe);
  EXPECT_NEAR(p.springs.edge, s.springs.edge, 1e-15);
  EXPECT_NEAR(p.kappa, 0.0, 1e-12);
  // The dissertation's material (E = 9 kPa, nu = 0.47) in the seed profile: G = 3600 Pa instead
  // of 3061 Pa, and the block's Young's modulus and Poisson ratio come out as
  // E = G (3 kappa + 5G)/(kappa + 2G) = 10.55 kPa, nu = (kappa + G)/(2 (kappa + 2G)) = 0.4655
  // (eq. 4.20).
  const LatticeModuli seed =
      lattice_moduli(polymer_stiffness(ShearModulusRule::two_fifths_youngs, kE, kNu, kLe), kLe);
  EXPECT_NEAR(seed.shear_modulus, 3600.0, 1e-9);
  const double kappa = extra_bulk_modulus(kE, kNu);
  EXPECT_NEAR(kappa, 44897.959, 1e-3);
  EXPECT_NEAR(seed.youngs_modulus, 3600 * (3 * kappa + 18000) / (kappa + 7200), 1e-6);
  EXPECT_NEAR(seed.youngs_modulus, 10551.2, 0.1);
  EXPECT_NEAR(seed.poisson_ratio, 0.5 * (kappa + 3600) / (kappa + 7200), 1e-12);
  EXPECT_NEAR(seed.poisson_ratio, 0.4655, 1e-4);
  const LatticeModuli phys = lattice_moduli(
      polymer_stiffness(ShearModulusRule::from_youngs_and_poisson, kE, kNu, kLe), kLe);
  EXPECT_NEAR(phys.shear_modulus, 3061.2245, 1e-4);  // the dissertation's "3.061 kPa"
}

// The physical derivation checked independently: energy density of one periodic cell under
// affine deformations, from its springs and the volume term (eq. 4.16), differentiated twice.
TEST(LatticeStiffness, AffineCellEnergyGivesTheUsersModuli) {
  for (const double nu : {-0.3, 0.1, 0.25, 0.47}) {
    for (const double a : {1.0, 0.3}) {
      const LatticeStiffness s =
          polymer_stiffness(ShearModulusRule::from_youngs_and_poisson, kE, nu, kLe, a);
      const auto m = testing::measure_moduli(
          [&](const Eigen::Matrix3d& f) { return testing::cell_energy_density(s, kLe, f); });
      const double tol = 1e-6 * kE / (1 - 2 * nu);
      EXPECT_NEAR(m.shear, kE / (2 * (1 + nu)), tol) << nu << " " << a;
      EXPECT_NEAR(m.bulk, kE / (3 * (1 - 2 * nu)), tol) << nu << " " << a;
      EXPECT_NEAR(m.c11, kE * (1 - nu) / ((1 + nu) * (1 - 2 * nu)), tol) << nu << " " << a;
      EXPECT_NEAR(m.youngs, kE, tol) << nu << " " << a;
      EXPECT_NEAR(m.poisson, nu, 1e-6) << nu << " " << a;
    }
  }
  const LatticeStiffness seed =
      polymer_stiffness(ShearModulusRule::two_fifths_youngs, kE, kNu, kLe);
  const auto m = testing::measure_moduli(
      [&](const Eigen::Matrix3d& f) { return testing::cell_energy_density(seed, kLe, f); });
  EXPECT_NEAR(m.shear, 0.4 * kE, 1e-6 * kE);
  EXPECT_NEAR(m.youngs, lattice_moduli(seed, kLe).youngs_modulus, 1e-5 * kE);
}

TEST(LatticeStiffness, PoissonRatioValidation) {
  for (const double nu : {0.5, -1.0, 0.6, -1.5, std::numeric_limits<double>::quiet_NaN()}) {
    EXPECT_THROW(validate_poisson_ratio(nu), std::invalid_argument) << nu;
    EXPECT_THROW(polymer_stiffness(ShearModulusRule::from_youngs_and_poisson, kE, nu, kLe),
                 std::invalid_argument);
  }
  EXPECT_NO_THROW(validate_poisson_ratio(0.4999));
  EXPECT_NO_THROW(validate_poisson_ratio(-0.9999));
  try {
    validate_poisson_ratio(0.5);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("poisson_ratio = 0.5"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("(-1, 0.5)"), std::string::npos);
  }
  EXPECT_THROW(polymer_stiffness(ShearModulusRule::two_fifths_youngs, -1.0, kNu, kLe),
               std::invalid_argument);
  EXPECT_THROW(polymer_stiffness(ShearModulusRule::two_fifths_youngs, kE, kNu, kLe, -1.0),
               std::invalid_argument);
}

// kappa < 0 below nu = 1/4 in both profiles; the bulk modulus stays positive in the physical
// profile but turns negative in the seed profile below nu = (1 - sqrt(3/2))/2.
TEST(LatticeStiffness, NegativeKappaBelowOneQuarter) {
  EXPECT_TRUE(kappa_nonnegative(0.25));
  EXPECT_FALSE(kappa_nonnegative(0.2499));
  EXPECT_LT(extra_bulk_modulus(kE, 0.2), 0.0);
  EXPECT_NEAR(seed_bulk_stability_limit(), -0.11237, 1e-5);
  const double lim = seed_bulk_stability_limit();
  const auto seed_bulk = [&](double nu) {
    return lattice_moduli(polymer_stiffness(ShearModulusRule::two_fifths_youngs, kE, nu, kLe), kLe)
        .bulk_modulus;
  };
  EXPECT_NEAR(seed_bulk(lim), 0.0, 1e-9 * kE);
  EXPECT_GT(seed_bulk(lim + 1e-3), 0.0);
  EXPECT_LT(seed_bulk(lim - 1e-3), 0.0);
  for (const double nu : {-0.99, -0.5, 0.0}) {
    EXPECT_GT(lattice_moduli(
                  polymer_stiffness(ShearModulusRule::from_youngs_and_poisson, kE, nu, kLe), kLe)
                  .bulk_modulus,
              0.0);
  }
}

// Section 4.2.2: particle springs are 1e4 x stiffer, or use iron's E if that is smaller.
TEST(LatticeStiffness, ParticleSprings) {
  EXPECT_DOUBLE_EQ(particle_youngs_modulus(9e3), 9e7);
  EXPECT_DOUBLE_EQ(particle_youngs_modulus(1e8), 2.11e11);
  for (const ShearModulusRule p :
       {ShearModulusRule::from_youngs_and_poisson, ShearModulusRule::two_fifths_youngs}) {
    const SpringConstants k = particle_spring_constants(p, kE, kNu, kLe);
    const SpringConstants poly = polymer_stiffness(p, kE, kNu, kLe).springs;
    EXPECT_NEAR(k.edge / poly.edge, 1e4, 1e-8);
    EXPECT_NEAR(k.face / poly.face, 1e4, 1e-8);
    EXPECT_NEAR(k.body / poly.body, 1e4, 1e-8);
  }
}

}  // namespace
}  // namespace mresim::lattice
