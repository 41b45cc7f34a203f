// Tests of the effective-modulus analysis of the 3D model (Section 4.2.8;
// docs/original-code.md#energies-and-moduli): exact recovery of a and c from synthetic parabolas,
// residuals of noise with a known rms, the split rule at a clustering kink, degenerate inputs, the
// stress-strain slope and the MR effect.

#include "mresim/mess/analysis/modulus_fit.hpp"

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <Eigen/QR>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

namespace ma = mresim::mess_analysis;

namespace {

constexpr double kModulus = 4000.0;  // Pa, the order of G_eff in Section 4.3

std::vector<double> strains(double first, double step, int count) {
  std::vector<double> x;
  for (int i = 0; i < count; ++i) x.push_back(first + step * i);
  return x;
}

std::vector<double> parabola(const std::vector<double>& x, double a, double c) {
  std::vector<double> u;
  for (double xi : x) u.push_back(0.5 * a * xi * xi + c);
  return u;
}

// A noise vector with the given rms that is orthogonal to the model's columns (x^2/2 and 1):
// least squares then returns the noiseless a and c exactly and the noise as the residual.
std::vector<double> orthogonal_noise(const std::vector<double>& x, double rms) {
  const auto n = static_cast<Eigen::Index>(x.size());
  Eigen::VectorXd e(n);
  for (Eigen::Index i = 0; i < n; ++i) e(i) = (i % 2 == 0 ? 1.0 : -1.0) + 0.3 * std::sin(i);
  Eigen::MatrixXd basis(n, 2);
  for (Eigen::Index i = 0; i < n; ++i) {
    basis(i, 0) = 0.5 * x[static_cast<std::size_t>(i)] * x[static_cast<std::size_t>(i)];
    basis(i, 1) = 1.0;
  }
  const Eigen::MatrixXd q = basis.householderQr().householderQ() * Eigen::MatrixXd::Identity(n, 2);
  e -= q * (q.transpose() * e);
  e *= rms / std::sqrt(e.squaredNorm() / static_cast<double>(n));
  return {e.data(), e.data() + n};
}

}  // namespace

TEST(MessModulusFit, CleanParabolaThroughOrigin) {
  const auto x = strains(0.0, 0.01, 11);
  const auto fit = ma::fit_energy_density(x, parabola(x, kModulus, 0.0));
  ASSERT_TRUE(fit.valid);
  EXPECT_FALSE(fit.split);
  EXPECT_EQ(fit.points, x.size());
  EXPECT_NEAR(fit.modulus, kModulus, 1e-9 * kModulus);
  EXPECT_NEAR(fit.offset, 0.0, 1e-12 * kModulus);
  EXPECT_LT(fit.rms_residual, 1e-12 * kModulus);
}

TEST(MessModulusFit, ParabolaWithOffset) {
  // A non-zero c: the field's magnetic energy at zero strain (Fig. 4.15g).
  const double c = -2.5e3;
  const auto x = strains(0.0, 0.02, 6);
  const auto fit = ma::fit_energy_density(x, parabola(x, 16.8e3, c));
  ASSERT_TRUE(fit.valid);
  EXPECT_FALSE(fit.split);
  EXPECT_NEAR(fit.modulus, 16.8e3, 1e-9 * 16.8e3);
  EXPECT_NEAR(fit.offset, c, 1e-12 * std::abs(c));
}

TEST(MessModulusFit, NegativeShearStrains) {
  // Shear runs may go both ways; u depends on x^2 only.
  for (const auto& x : {strains(-0.1, 0.02, 11), strains(0.0, -0.01, 8)}) {
    const auto fit = ma::fit_energy_density(x, parabola(x, kModulus, 12.0));
    ASSERT_TRUE(fit.valid);
    EXPECT_FALSE(fit.split);
    EXPECT_EQ(fit.points, x.size());
    EXPECT_NEAR(fit.modulus, kModulus, 1e-9 * kModulus);
    EXPECT_NEAR(fit.offset, 12.0, 1e-10 * 12.0);
  }
}

TEST(MessModulusFit, NoiseWithKnownRms) {
  const auto x = strains(0.0, 0.01, 12);
  auto u = parabola(x, kModulus, 3.0);
  // rms 0.01 J/m^3 against second differences a dx^2 = 0.4: the increments still grow.
  const double rms = 0.01;
  const auto e = orthogonal_noise(x, rms);
  for (std::size_t i = 0; i < u.size(); ++i) u[i] += e[i];
  const auto fit = ma::fit_energy_density(x, u);
  ASSERT_TRUE(fit.valid);
  EXPECT_FALSE(fit.split);
  EXPECT_NEAR(fit.modulus, kModulus, 1e-9 * kModulus);
  EXPECT_NEAR(fit.offset, 3.0, 1e-9);
  EXPECT_NEAR(fit.rms_residual, rms, 1e-9 * rms);
}

TEST(MessModulusFit, SplitsAtDropAfterKink) {
  // Particles snap together at the 6th strain: the energy density drops, then rises again.
  const auto x = strains(0.0, 0.01, 9);
  auto u = parabola(x, kModulus, 0.0);
  for (std::size_t i = 5; i < u.size(); ++i) u[i] -= 1.5;
  const auto fit = ma::fit_energy_density(x, u);
  ASSERT_TRUE(fit.valid);
  EXPECT_TRUE(fit.split);
  EXPECT_EQ(fit.points, 5u);
  EXPECT_NEAR(fit.modulus, kModulus, 1e-9 * kModulus);
  EXPECT_LT(fit.rms_residual, 1e-12 * kModulus);
}

TEST(MessModulusFit, SplitsWhereIncrementsShrinkWithoutDrop) {
  // Still increasing after the kink, but more slowly (softer clustered state).
  const auto x = strains(0.0, 0.01, 8);
  auto u = parabola(x, kModulus, 1.0);
  for (std::size_t i = 4; i < u.size(); ++i) u[i] = u[3] + 0.01 * static_cast<double>(i - 3);
  const auto fit = ma::fit_energy_density(x, u);
  EXPECT_TRUE(fit.split);
  EXPECT_EQ(fit.points, 4u);
  EXPECT_NEAR(fit.modulus, kModulus, 1e-9 * kModulus);
  EXPECT_NEAR(fit.offset, 1.0, 1e-9);
}

TEST(MessModulusFit, JumpUpIsNotCut) {
  // A larger increment is not a kink: the last point jumping up stays in the fit.
  const auto x = strains(0.0, 0.01, 6);
  auto u = parabola(x, kModulus, 0.0);
  u.back() += 5.0;
  const auto fit = ma::fit_energy_density(x, u);
  ASSERT_TRUE(fit.valid);
  EXPECT_FALSE(fit.split);
  EXPECT_EQ(fit.points, x.size());
  EXPECT_GT(fit.rms_residual, 0.1);
}

TEST(MessModulusFit, JumpUpInsideCurveIsKeptAndCutAfter) {
  // The jump itself is kept; the ordinary increment after it is smaller than the jump and
  // cuts there (the rule compares neighbouring increments only).
  const auto x = strains(0.0, 0.01, 8);
  auto u = parabola(x, kModulus, 0.0);
  for (std::size_t i = 4; i < u.size(); ++i) u[i] += 5.0;
  const auto fit = ma::fit_energy_density(x, u);
  EXPECT_TRUE(fit.split);
  EXPECT_EQ(fit.points, 5u);
}

TEST(MessModulusFit, KinkBeforeThirdPointFitsAllPoints) {
  // Only 2 points before the cut: too few, so the whole curve is fitted and split stays false.
  const std::vector<double> x{0.0, 0.01, 0.02, 0.03};
  const std::vector<double> u{0.0, 1.0, 1.5, 4.0};
  const auto fit = ma::fit_energy_density(x, u);
  ASSERT_TRUE(fit.valid);
  EXPECT_FALSE(fit.split);
  EXPECT_EQ(fit.points, 4u);
}

TEST(MessModulusFit, TwoPointsAreNotAResult) {
  // Two points interpolate a and c exactly, with nothing left to check the parabola: the
  // numbers are kept (for marked plots) but the fit is invalid.
  const std::vector<double> x{0.0, 0.05};
  const auto fit = ma::fit_energy_density(x, parabola(x, kModulus, 7.0));
  EXPECT_FALSE(fit.valid);
  EXPECT_EQ(fit.points, 2u);
  EXPECT_NE(fit.problem.find("only 2 point(s)"), std::string::npos) << fit.problem;
  EXPECT_NEAR(fit.modulus, kModulus, 1e-9 * kModulus);
  EXPECT_NEAR(fit.offset, 7.0, 1e-9);
}

// Phi = 6 % at 140 mT (small example): three strains, the zero-strain point above the next is
// dropped and two points remain. Before, 12.6 kPa was reported as G_eff.
TEST(MessModulusFit, DroppedZeroPointLeavingTwoPointsIsInvalid) {
  const std::vector<double> x{0.0, 0.02, 0.04};
  auto u = parabola(x, kModulus, -100.0);
  u[0] = u[1] + 1.0;
  const auto fit = ma::fit_energy_density(x, u);
  EXPECT_EQ(fit.first, 1U);
  EXPECT_EQ(fit.points, 2U);
  EXPECT_FALSE(fit.valid);
  EXPECT_TRUE(std::isfinite(fit.modulus));
  EXPECT_NE(fit.problem.find("at least 3"), std::string::npos) << fit.problem;
}

TEST(MessModulusFit, UnconvergedFittedPointIsInvalid) {
  const auto x = strains(0.0, 0.01, 6);
  const auto u = parabola(x, kModulus, 0.0);
  ma::FitOptions options;
  options.converged = {true, true, true, false, true, true};
  const auto fit = ma::fit_energy_density(x, u, options);
  EXPECT_FALSE(fit.valid);
  EXPECT_NEAR(fit.modulus, kModulus, 1e-9 * kModulus);  // the numbers, for the marked plot
  EXPECT_NE(fit.problem.find("strain 0.03 did not converge"), std::string::npos) << fit.problem;
  // All converged: the same data is a result.
  options.converged.assign(x.size(), true);
  EXPECT_TRUE(ma::fit_energy_density(x, u, options).valid);
  // Flags of another length are a programming error.
  options.converged = {true};
  EXPECT_THROW(ma::fit_energy_density(x, u, options), std::invalid_argument);
}

TEST(MessModulusFit, UnconvergedPointAfterTheKinkDoesNotMatter) {
  // Only the fitted points count: the unconverged step lies behind the cut.
  const auto x = strains(0.0, 0.01, 9);
  auto u = parabola(x, kModulus, 0.0);
  for (std::size_t i = 5; i < u.size(); ++i) u[i] -= 1.5;
  ma::FitOptions options;
  options.converged.assign(x.size(), true);
  options.converged[7] = false;
  const auto fit = ma::fit_energy_density(x, u, options);
  EXPECT_TRUE(fit.split);
  EXPECT_EQ(fit.points, 5U);
  EXPECT_TRUE(fit.valid) << fit.problem;
}

TEST(MessModulusFit, NegativeCurvatureIsInvalid) {
  // Energy falling with |x| away from zero strain (strains not starting at 0, so no point
  // is compared with a zero-strain state): a < 0 is no modulus.
  const auto x = strains(0.01, 0.01, 5);
  const auto fit = ma::fit_energy_density(x, parabola(x, -kModulus, 50.0));
  EXPECT_FALSE(fit.valid);
  EXPECT_NEAR(fit.modulus, -kModulus, 1e-9 * kModulus);
  EXPECT_NE(fit.problem.find("curvature"), std::string::npos) << fit.problem;
}

// Torsion of the helix: the +2 deg point lies below the zero-twist state (a torque at zero
// twist); without the shear-only zero-point rule the symmetric parabola is refused.
TEST(MessModulusFit, PointBelowTheZeroStrainStateIsInvalid) {
  const double deg = 3.14159265358979 / 180.0;
  const std::vector<double> x{0.0, 2 * deg, 4 * deg, 6 * deg};
  std::vector<double> u;
  for (const double xi : x) u.push_back(0.5 * kModulus * xi * xi - 600.0 * xi);  // linear term
  ASSERT_LT(u[1], u[0]);
  ma::FitOptions options;
  options.drop_zero_point_above_next = false;
  const auto fit = ma::fit_energy_density(x, u, options);
  EXPECT_EQ(fit.first, 0U);
  EXPECT_FALSE(fit.valid);
  EXPECT_NE(fit.problem.find("below the zero-strain state"), std::string::npos) << fit.problem;
  // Equal to the zero-strain state is not below it.
  std::vector<double> flat = parabola(x, kModulus, 0.0);
  EXPECT_TRUE(ma::fit_energy_density(x, flat, options).valid);
}

TEST(MessModulusFit, NonFiniteFittedPointIsInvalid) {
  const auto x = strains(0.0, 0.01, 6);
  auto u = parabola(x, kModulus, 0.0);
  u[2] = std::numeric_limits<double>::quiet_NaN();
  const auto fit = ma::fit_energy_density(x, u);
  EXPECT_FALSE(fit.valid);
  EXPECT_NE(fit.problem.find("non-finite"), std::string::npos) << fit.problem;
  u[2] = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(ma::fit_energy_density(x, u).valid);
}

TEST(MessModulusFit, StressFitValidity) {
  const std::vector<double> e{0.0, 0.01, 0.02, 0.03};
  const std::vector<double> s{0.0, 90.0, 180.0, 270.0};
  EXPECT_TRUE(ma::fit_stress_strain(e, s).valid);
  // The both-faces stress run at 80 mT: a step hit its iteration limit.
  const auto unconverged = ma::fit_stress_strain(e, s, {true, true, false, true});
  EXPECT_FALSE(unconverged.valid);
  EXPECT_NEAR(unconverged.modulus, 9000.0, 1e-9);
  EXPECT_NE(unconverged.problem.find("stress 180 did not converge"), std::string::npos)
      << unconverged.problem;
  // One loaded point: a slope through the origin with nothing to check it.
  const auto one = ma::fit_stress_strain({0.0, 0.01}, {0.0, 90.0});
  EXPECT_FALSE(one.valid);
  EXPECT_NE(one.problem.find("only 1 loaded point"), std::string::npos) << one.problem;
  // Strain against the stress: a negative slope.
  const auto negative = ma::fit_stress_strain({0.0, -0.01, -0.02}, {0.0, 90.0, 180.0});
  EXPECT_FALSE(negative.valid);
  EXPECT_NE(negative.problem.find("not positive"), std::string::npos) << negative.problem;
  const auto nan = ma::fit_stress_strain({0.0, 0.01, std::numeric_limits<double>::quiet_NaN()},
                                         {0.0, 90.0, 180.0});
  EXPECT_FALSE(nan.valid);
}

TEST(MessModulusFit, UnderdeterminedIsInvalid) {
  const auto one = ma::fit_energy_density({0.01}, {2.0});
  EXPECT_FALSE(one.valid);
  EXPECT_EQ(one.points, 1u);
  const auto none = ma::fit_energy_density({}, {});
  EXPECT_FALSE(none.valid);
  EXPECT_EQ(none.points, 0u);
  // +-gamma only: x^2 takes one value, a and c are not separable.
  const auto symmetric = ma::fit_energy_density({-0.05, 0.05, -0.05}, {1.0, 1.0, 1.0});
  EXPECT_FALSE(symmetric.valid);
}

TEST(MessModulusFit, SizeMismatchThrows) {
  EXPECT_THROW(ma::fit_energy_density({0.0, 0.1}, {0.0}), std::invalid_argument);
  EXPECT_THROW(ma::fit_stress_strain({0.0, 0.1}, {0.0, 1.0, 2.0}), std::invalid_argument);
}

TEST(MessModulusFit, StressStrainSlopeThroughOrigin) {
  const std::vector<double> e{0.0, 0.01, 0.02, 0.03, 0.04};
  std::vector<double> s;
  for (double ei : e) s.push_back(9000.0 * ei);
  auto fit = ma::fit_stress_strain(e, s);
  ASSERT_TRUE(fit.valid);
  EXPECT_EQ(fit.points, e.size());
  EXPECT_NEAR(fit.modulus, 9000.0, 1e-9 * 9000.0);
  EXPECT_LT(fit.rms_residual, 1e-9);

  // Perturbation orthogonal to e: slope unchanged, residual rms known.
  const std::vector<double> d{1.0, 2.0, -1.0, 0.0, 0.0};  // d . e = 0.02 - 0.02 = 0
  for (std::size_t i = 0; i < s.size(); ++i) s[i] += d[i];
  fit = ma::fit_stress_strain(e, s);
  EXPECT_NEAR(fit.modulus, 9000.0, 1e-9 * 9000.0);
  EXPECT_NEAR(fit.rms_residual, std::sqrt(6.0 / 5.0), 1e-12);

  EXPECT_FALSE(ma::fit_stress_strain({0.0, 0.0}, {1.0, 2.0}).valid);
  EXPECT_FALSE(ma::fit_stress_strain({}, {}).valid);
}

TEST(MessModulusFit, MrEffectPercent) {
  EXPECT_NEAR(ma::mr_effect_percent(5000.0, 4000.0), 25.0, 1e-12);
  EXPECT_NEAR(ma::mr_effect_percent(16.8e3, 4.0e3), 320.0, 1e-10);
  EXPECT_EQ(ma::mr_effect_percent(4000.0, 4000.0), 0.0);
  EXPECT_NEAR(ma::mr_effect_percent(3000.0, 4000.0), -25.0, 1e-12);
  EXPECT_TRUE(std::isnan(ma::mr_effect_percent(5000.0, 0.0)));
  EXPECT_TRUE(std::isnan(ma::mr_effect_percent(5000.0, -1.0)));
  EXPECT_TRUE(std::isnan(ma::mr_effect_percent(5000.0, std::numeric_limits<double>::quiet_NaN())));
}

// docs/original-code.md#energies-and-moduli: a zero-strain point above the next one is not fitted.
TEST(MessModulusFit, ZeroStrainPointAboveTheNextIsDropped) {
  const auto x = strains(0.0, 0.01, 6);
  auto u = parabola(x, kModulus, -3387.0);
  u[0] += 0.5;  // above u[1] = c + a 1e-4 / 2 = c + 0.2
  const auto fit = ma::fit_energy_density(x, u);
  ASSERT_TRUE(fit.valid);
  EXPECT_EQ(fit.first, 1U);
  EXPECT_EQ(fit.points, 5U);
  EXPECT_FALSE(fit.split);
  EXPECT_NEAR(fit.modulus, kModulus, 1e-6 * kModulus);
  EXPECT_NEAR(fit.offset, -3387.0, 1e-9);
  // Below the next point it stays.
  u[0] -= 0.45;
  EXPECT_EQ(ma::fit_energy_density(x, u).first, 0U);
}
