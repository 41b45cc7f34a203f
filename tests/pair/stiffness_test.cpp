#include "mresim/pair/stiffness.hpp"

#include <gtest/gtest.h>

namespace mresim::pair {
namespace {

// Claim C1 (Section 2.5.3): G = 1375 Pa, R = 1.5 um, S0 = 9 um.
TEST(PuljizStiffness, ReproducesTheThreeSpringConstantsOfFigure27) {
  const PuljizStiffness k = puljiz_stiffness(1375.0, 1.5e-6, 9e-6);
  EXPECT_NEAR(k.k0, 3.133e-2, 0.0005e-2);
  EXPECT_NEAR(k.k12, 1.015e-2, 0.0005e-2);
}

// Claim C2 (Fig. 2.6 caption): the three-spring equivalent of k = 4e-2 N/m.
TEST(PuljizStiffness, EquivalentSingleSpringOfFigure26) {
  const PuljizStiffness unit = puljiz_stiffness(1.0, 1.5e-6, 9e-6);
  const double shear_modulus = 4e-2 / unit.equivalent_single();
  const PuljizStiffness k = puljiz_stiffness(shear_modulus, 1.5e-6, 9e-6);
  EXPECT_NEAR(k.k0, 4.855e-2, 0.001e-2);
  EXPECT_NEAR(k.k12, 1.572e-2, 0.001e-2);
  EXPECT_NEAR(k.equivalent_single(), 4e-2, 1e-15);
}

// Section 3.6: k = 9e-3 and 9e-1 N/m at S0 = 12 um are "E ~ 8 kPa and ~ 800 kPa".
TEST(YoungsModulusConversion, ChapterThreeCylinder) {
  EXPECT_NEAR(youngs_from_spring_chapter3(9e-3, 1.5e-6, 12e-6), 7.64e3, 0.01e3);
  EXPECT_NEAR(youngs_from_spring_chapter3(9e-1, 1.5e-6, 12e-6), 764e3, 1e3);
  EXPECT_NEAR(
      spring_from_youngs_chapter3(youngs_from_spring_chapter3(0.3, 1.5e-6, 7e-6), 1.5e-6, 7e-6),
      0.3, 1e-15);
}

// Section 2.4: k = E pi R^2 / S0; the Chapter 2 cylinder gives twice the Chapter 3 modulus.
TEST(YoungsModulusConversion, ChapterTwoCylinder) {
  EXPECT_NEAR(spring_from_youngs_chapter2(1e4, 1.5e-6, 9e-6),
              1e4 * 3.141592653589793 * 2.25e-12 / 9e-6, 1e-15);
  EXPECT_NEAR(youngs_from_spring_chapter2(9e-3, 1.5e-6, 12e-6),
              2.0 * youngs_from_spring_chapter3(9e-3, 1.5e-6, 12e-6), 1e-9);
}

// By eq. 2.10 S0 = 12.2 um clusters only for k below about 1.06e-2 N/m (claim C5 in
// docs/validation.md, not "k <= 0.1 N/m" as Section 2.6 says).
TEST(ClusteringThreshold, Equation210) {
  const SphereMaterial iron;
  EXPECT_NEAR(clustering_threshold_stiffness(iron, 12.2e-6), 1.06e-2, 0.01e-2);
  const double s0 = clustering_threshold_separation(iron, 2.5e-2);
  EXPECT_NEAR(clustering_threshold_stiffness(iron, s0), 2.5e-2, 1e-15);
}

// Claim C11: S0_avg = (V/Phi)^(1/3) = 7.8 um for Phi = 0.03, R = 1.5 um.
TEST(MeanSeparation, ThreePercentFillingFraction) {
  EXPECT_NEAR(mean_separation(1.5e-6, 0.03), 7.8e-6, 0.05e-6);
}

}  // namespace
}  // namespace mresim::pair
