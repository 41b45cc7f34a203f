// Tests of the fit after a clustering kink (src/mresim/mess/analysis/second_fit.hpp; Figs.
// 4.25-4.26): exact recovery of a, b and c of u = a x^2/2 + b x + c from a synthetic curve with
// a kink, the rules for too few points, no kink, unconverged and non-finite points, and the
// curvature's sign.

#include "mresim/mess/analysis/second_fit.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

namespace ma = mresim::mess_analysis;

namespace {

constexpr double kFirst = 4000.0;   // Pa, the unclustered branch (Fig. 4.25's order)
constexpr double kSecond = 9500.0;  // Pa, the clustered branch after the kink
constexpr double kSlope = -120.0;   // J/m^3, b of the second branch
constexpr double kOffset = -35.0;   // J/m^3, c of the second branch

// The strains 0, 0.01, 0.02, ... (`count` of them).
std::vector<double> percent_strains(int count) {
  std::vector<double> x;
  for (int i = 0; i < count; ++i) x.push_back(0.01 * i);
  return x;
}

// u = kFirst x^2/2 + 2 up to x_k = 0.01 (kink - 1), then the clustered branch
// kSecond x^2/2 + kSlope x + kOffset, which lies well below (the energy drops at the snap).
std::vector<double> kinked(const std::vector<double>& x, std::size_t kink) {
  std::vector<double> u;
  for (std::size_t i = 0; i < x.size(); ++i) {
    const double xi = x[i];
    u.push_back(i < kink ? 0.5 * kFirst * xi * xi + 2.0
                         : 0.5 * kSecond * xi * xi + kSlope * xi + kOffset);
  }
  return u;
}

}  // namespace

TEST(MessSecondFit, RecoversTheBranchAfterTheKinkExactly) {
  const auto x = percent_strains(11);  // 0 ... 0.1, kink at 0.03 as in Fig. 4.27
  const auto u = kinked(x, 3);
  const ma::QuadraticFit first = ma::fit_energy_density(x, u);
  ASSERT_TRUE(first.valid) << first.problem;
  ASSERT_TRUE(first.split);
  EXPECT_EQ(first.points, 3u);
  EXPECT_NEAR(first.modulus, kFirst, 1e-9 * kFirst);

  const ma::SecondFit second = ma::fit_after_kink(x, u, first);
  ASSERT_TRUE(second.valid) << second.problem;
  EXPECT_EQ(second.first, 3u);
  EXPECT_EQ(second.points, 8u);
  EXPECT_NEAR(second.modulus, kSecond, 1e-9 * kSecond);
  EXPECT_NEAR(second.slope, kSlope, 1e-9 * std::abs(kSlope));
  EXPECT_NEAR(second.offset, kOffset, 1e-9 * std::abs(kOffset));
  EXPECT_LT(second.rms_residual, 1e-9);
}

TEST(MessSecondFit, FollowsTheDroppedZeroPoint) {
  // Shear: the zero-strain point above the next one is dropped (first = 1); the kink point is
  // then first + points of the first fit.
  const auto x = percent_strains(10);
  auto u = kinked(x, 5);
  u[0] = u[1] + 1.0;
  const ma::QuadraticFit first = ma::fit_energy_density(x, u);
  ASSERT_EQ(first.first, 1u);
  ASSERT_TRUE(first.split);
  EXPECT_EQ(first.points, 4u);
  const ma::SecondFit second = ma::fit_after_kink(x, u, first);
  ASSERT_TRUE(second.valid) << second.problem;
  EXPECT_EQ(second.first, 5u);
  EXPECT_EQ(second.points, 5u);
  EXPECT_NEAR(second.modulus, kSecond, 1e-9 * kSecond);
}

TEST(MessSecondFit, NoKinkNoSecondFit) {
  const auto x = percent_strains(8);
  std::vector<double> u;
  for (double xi : x) u.push_back(0.5 * kFirst * xi * xi);
  const ma::QuadraticFit first = ma::fit_energy_density(x, u);
  ASSERT_FALSE(first.split);
  const ma::SecondFit second = ma::fit_after_kink(x, u, first);
  EXPECT_FALSE(second.valid);
  EXPECT_EQ(second.problem, "no kink");
  EXPECT_EQ(second.points, 0u);
  EXPECT_TRUE(std::isnan(second.modulus));
  EXPECT_TRUE(std::isnan(second.slope));
  EXPECT_TRUE(std::isnan(second.offset));
}

TEST(MessSecondFit, TwoPointsAfterTheKinkAreUndetermined) {
  const auto x = percent_strains(6);
  const auto u = kinked(x, 4);  // points 4 and 5 after the kink
  const ma::QuadraticFit first = ma::fit_energy_density(x, u);
  ASSERT_TRUE(first.split);
  const ma::SecondFit second = ma::fit_after_kink(x, u, first);
  EXPECT_FALSE(second.valid);
  EXPECT_EQ(second.first, 4u);
  EXPECT_EQ(second.points, 2u);
  EXPECT_TRUE(std::isnan(second.modulus));
  EXPECT_NE(second.problem.find("only 2 point(s)"), std::string::npos) << second.problem;
}

TEST(MessSecondFit, ThreePointsInterpolateAndAreNotAResult) {
  // Three points fix a, b, c exactly (the numbers are right) but check nothing.
  const auto x = percent_strains(7);
  const auto u = kinked(x, 4);
  const ma::QuadraticFit first = ma::fit_energy_density(x, u);
  ASSERT_TRUE(first.split);
  const ma::SecondFit second = ma::fit_after_kink(x, u, first);
  EXPECT_EQ(second.points, 3u);
  EXPECT_NEAR(second.modulus, kSecond, 1e-8 * kSecond);
  EXPECT_NEAR(second.slope, kSlope, 1e-8 * std::abs(kSlope));
  EXPECT_FALSE(second.valid);
  EXPECT_NE(second.problem.find("only 3 point(s)"), std::string::npos) << second.problem;
}

TEST(MessSecondFit, UnconvergedPointAfterTheKinkIsInvalid) {
  const auto x = percent_strains(11);
  const auto u = kinked(x, 3);
  ma::FitOptions options;
  options.converged.assign(x.size(), true);
  options.converged[7] = false;
  const ma::QuadraticFit first = ma::fit_energy_density(x, u, options);
  ASSERT_TRUE(first.valid);  // the point is after the first fit's points
  const ma::SecondFit second = ma::fit_after_kink(x, u, first, options);
  EXPECT_FALSE(second.valid);
  EXPECT_NE(second.problem.find("did not converge"), std::string::npos) << second.problem;
  EXPECT_NEAR(second.modulus, kSecond, 1e-9 * kSecond);  // the numbers are kept
}

TEST(MessSecondFit, NonFinitePointIsInvalid) {
  const auto x = percent_strains(11);
  auto u = kinked(x, 3);
  const ma::QuadraticFit first = ma::fit_energy_density(x, u);
  u[9] = std::numeric_limits<double>::quiet_NaN();
  const ma::SecondFit second = ma::fit_after_kink(x, u, first);
  EXPECT_FALSE(second.valid);
  EXPECT_NE(second.problem.find("non-finite point"), std::string::npos) << second.problem;
}

TEST(MessSecondFit, NegativeCurvatureIsInvalid) {
  // A concave branch after the kink (the clustered state softening further) is no modulus.
  const auto x = percent_strains(9);
  auto u = kinked(x, 4);
  for (std::size_t i = 4; i < x.size(); ++i) u[i] = -0.5 * 3000.0 * x[i] * x[i] - 10.0;
  const ma::QuadraticFit first = ma::fit_energy_density(x, u);
  ASSERT_TRUE(first.split);
  const ma::SecondFit second = ma::fit_after_kink(x, u, first);
  EXPECT_FALSE(second.valid);
  EXPECT_NEAR(second.modulus, -3000.0, 1e-9 * 3000.0);
  EXPECT_NE(second.problem.find("not positive"), std::string::npos) << second.problem;
}

TEST(MessSecondFit, RepeatedStrainsAreUndetermined) {
  // Three points after the kink at only two strains leave a, b, c undetermined.
  const std::vector<double> x = {0.0, 0.01, 0.02, 0.03, 0.03, 0.04};
  std::vector<double> u = {0.0, 0.2, 0.8, -5.0, -5.0, -4.0};
  const ma::QuadraticFit first = ma::fit_energy_density(x, u);
  ASSERT_TRUE(first.split);
  const ma::SecondFit second = ma::fit_after_kink(x, u, first);
  EXPECT_FALSE(second.valid);
  EXPECT_TRUE(std::isnan(second.modulus));
  EXPECT_NE(second.problem.find("fewer than 3 values"), std::string::npos) << second.problem;
}

TEST(MessSecondFit, SizeMismatchThrows) {
  const ma::QuadraticFit first;
  EXPECT_THROW(ma::fit_after_kink({0.0, 0.1}, {0.0}, first), std::invalid_argument);
  ma::FitOptions options;
  options.converged = {true};
  EXPECT_THROW(ma::fit_after_kink({0.0, 0.1}, {0.0, 1.0}, first, options), std::invalid_argument);
}
