#include "mresim/pair/pair_magnetization.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>

namespace mresim::pair {
namespace {

// Eqs. 2.5-2.7 for two spheres in 3D, assembled independently: [I, -chi D; -chi D, I] x = chi h.
Eigen::Matrix<double, 6, 1> solve_linear_system(const Eigen::Vector3d& d, const Eigen::Vector3d& h,
                                                double chi) {
  const double s = d.norm();
  const Eigen::Vector3d n = d / s;
  const Eigen::Matrix3d coupling =
      (3.0 * n * n.transpose() - Eigen::Matrix3d::Identity()) / (3.0 * s * s * s);
  Eigen::Matrix<double, 6, 6> a = Eigen::Matrix<double, 6, 6>::Identity();
  a.block<3, 3>(0, 3) = -chi * coupling;
  a.block<3, 3>(3, 0) = -chi * coupling;
  Eigen::Matrix<double, 6, 1> b;
  b << chi * h, chi * h;
  return a.fullPivLu().solve(b);
}

TEST(PairMagnetization, MatchesTheLinearSystemBelowSaturation) {
  const Eigen::Vector3d d(2.5, 0.7, -1.1);
  const Eigen::Vector3d h(0.08, -0.05, 0.11);
  const PairMagnetization mag = solve_pair_magnetization(d, h, 2.0);
  const auto x = solve_linear_system(d, h, 2.0);
  EXPECT_FALSE(mag.saturated);
  EXPECT_LT((mag.m - x.head<3>()).norm(), 1e-14);
  EXPECT_LT((mag.m - x.tail<3>()).norm(), 1e-14);  // m1 = m2
}

TEST(PairMagnetization, SaturatedMomentIsUnitAndParallelToItsEffectiveField) {
  for (double angle : {0.0, 0.3, 1.2, 1.5707963267948966, 2.5}) {
    const Eigen::Vector3d d(2.2, 0.0, 0.4);
    const Eigen::Vector3d h = 0.9 * Eigen::Vector3d(std::cos(angle), 0.0, std::sin(angle));
    const PairMagnetization mag = solve_pair_magnetization(d, h, 2.0);
    ASSERT_TRUE(mag.saturated) << angle;
    EXPECT_NEAR(mag.m.norm(), 1.0, 1e-14);
    const Eigen::Vector3d h_eff = h + dipole_coupling(d) * mag.m;
    EXPECT_LT((mag.m - h_eff.normalized()).norm(), 1e-12) << angle;
  }
}

// The magnetization minimises -m.h + m^2/(2 chi) - m.D m/2 over the unit ball (Section 2.4
// energy with m1 = m2), so no admissible perturbation may lower it.
TEST(PairMagnetization, IsTheConstrainedMinimiserOfTheMagneticEnergy) {
  const Eigen::Vector3d d(2.1, 0.0, 0.9);
  const double chi = 2.0;
  const Eigen::Matrix3d coupling = dipole_coupling(d);
  auto functional = [&](const Eigen::Vector3d& m, const Eigen::Vector3d& h) {
    return -m.dot(h) + m.squaredNorm() / (2.0 * chi) - 0.5 * m.dot(coupling * m);
  };
  for (double magnitude : {0.1, 0.4, 0.7, 2.0}) {
    const Eigen::Vector3d h = magnitude * Eigen::Vector3d(0.6, 0.0, 0.8);
    const Eigen::Vector3d m = solve_pair_magnetization(d, h, chi).m;
    const double best = functional(m, h);
    for (int i = 0; i < 200; ++i) {
      Eigen::Vector3d trial = m + 1e-3 * Eigen::Vector3d::Random();
      if (trial.norm() > 1.0) trial.normalize();
      EXPECT_GE(functional(trial, h), best - 1e-15) << magnitude;
    }
  }
}

TEST(PairMagnetization, AxialAndTransverseResponsesFollowTheCouplingEigenvalues) {
  const double s = 2.0;  // contact
  const double a = 1.0 / (3.0 * s * s * s);
  const double h = 0.05;
  const auto axial = solve_pair_magnetization({s, 0, 0}, {h, 0, 0}, 2.0);
  const auto transverse = solve_pair_magnetization({s, 0, 0}, {0, 0, h}, 2.0);
  EXPECT_NEAR(axial.m.x(), h / (0.5 - 2.0 * a), 1e-15);  // enhanced along the axis
  EXPECT_NEAR(transverse.m.z(), h / (0.5 + a), 1e-15);   // reduced across it
}

}  // namespace
}  // namespace mresim::pair
