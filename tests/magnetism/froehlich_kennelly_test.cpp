// Tests of the anhysteretic magnetization laws, eqs. 1.4 and 1.5 (Section 1.3.3, Fig. 1.6).

#include "mresim/magnetism/froehlich_kennelly.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <cstddef>
#include <stdexcept>

#include "../support/dissertation_values.hpp"
#include "mresim/core/constants.hpp"
#include "mresim/magnetism/loop_features.hpp"

namespace mm = mresim::magnetism;

namespace {

// Carbonyl-iron-like parameters of Fig. 1.6.
constexpr double kChi0 = 70.0;
using mresim::testing::kMs;  // 1.6e6 A/m

}  // namespace

TEST(FroehlichKennellyTest, LowFieldSlopeIsInitialSusceptibility) {
  // chi0 |H| << Ms: M ~ chi0 H (eq. 1.4 limit), with relative correction -chi0 |H| / Ms.
  const double H = 1.0;  // A/m, chi0 H / Ms = 4.4e-5
  EXPECT_NEAR(mm::froehlich_kennelly(H, kChi0, kMs) / H, kChi0, kChi0 * 1e-4);
  EXPECT_LT(mm::froehlich_kennelly(H, kChi0, kMs) / H, kChi0);  // already sub-linear
  EXPECT_DOUBLE_EQ(mm::froehlich_kennelly_derivative(0.0, kChi0, kMs), kChi0);
  const Eigen::Vector3d small(0.3, -0.4, 0.5);
  const Eigen::Vector3d m = mm::froehlich_kennelly(small, kChi0, kMs);
  EXPECT_TRUE(m.isApprox(kChi0 * small, 1e-4));
  EXPECT_TRUE(mm::froehlich_kennelly_jacobian(Eigen::Vector3d::Zero(), kChi0, kMs)
                  .isApprox(kChi0 * Eigen::Matrix3d::Identity(), 1e-15));
}

TEST(FroehlichKennellyTest, ApproachesSaturationFromBelow) {
  double previous = 0.0;
  for (double H : {1e4, 1e5, 1e6, 1e7, 1e8, 1e10}) {
    const double m = mm::froehlich_kennelly(H, kChi0, kMs);
    EXPECT_GT(m, previous);
    EXPECT_LT(m, kMs);
    // Ms - M = Ms^2 / (Ms + chi0 H): the deficit falls off like 1/H.
    EXPECT_NEAR(kMs - m, kMs * kMs / (kMs + kChi0 * H), 1e-9 * kMs);
    previous = m;
  }
  EXPECT_NEAR(mm::froehlich_kennelly(1e10, kChi0, kMs) / kMs, 1.0, 1e-5);
  EXPECT_GT(kMs - mm::froehlich_kennelly(1e6, kChi0, kMs), 0.02 * kMs);  // not yet saturated
}

TEST(FroehlichKennellyTest, CollinearWithFieldAndMatchesScalarForm) {
  const std::array<Eigen::Vector3d, 4> fields = {
      Eigen::Vector3d(1e5, 0, 0), Eigen::Vector3d(-2e4, 3e5, 7e3), Eigen::Vector3d(4e6, -4e6, 1e6),
      Eigen::Vector3d(0, 0, -9e2)};
  for (const Eigen::Vector3d& H : fields) {
    const Eigen::Vector3d m = mm::froehlich_kennelly(H, kChi0, kMs);
    EXPECT_LT(m.cross(H).norm(), 1e-12 * m.norm() * H.norm());
    EXPECT_GT(m.dot(H), 0.0);
    EXPECT_NEAR(m.norm(), mm::froehlich_kennelly(H.norm(), kChi0, kMs), 1e-9 * kMs);
  }
}

TEST(FroehlichKennellyTest, IsOddInField) {
  for (double H : {0.0, 10.0, 3e4, 2e5, 5e6}) {
    EXPECT_DOUBLE_EQ(mm::froehlich_kennelly(-H, kChi0, kMs),
                     -mm::froehlich_kennelly(H, kChi0, kMs));
    EXPECT_DOUBLE_EQ(mm::froehlich_kennelly_derivative(-H, kChi0, kMs),
                     mm::froehlich_kennelly_derivative(H, kChi0, kMs));
  }
  const Eigen::Vector3d H(1.2e5, -3e4, 8e4);
  EXPECT_TRUE(mm::froehlich_kennelly(Eigen::Vector3d(-H), kChi0, kMs)
                  .isApprox(-mm::froehlich_kennelly(H, kChi0, kMs), 1e-15));
}

TEST(FroehlichKennellyTest, JacobianMatchesCentralFiniteDifferences) {
  const std::array<Eigen::Vector3d, 5> fields = {
      Eigen::Vector3d(1e3, 2e3, -5e2), Eigen::Vector3d(2.3e4, 0, 0),
      Eigen::Vector3d(-1e5, 4e5, 2e5), Eigen::Vector3d(3e6, -1e6, 5e5), Eigen::Vector3d(0, 0, 8e7)};
  for (const Eigen::Vector3d& H : fields) {
    const Eigen::Matrix3d analytic = mm::froehlich_kennelly_jacobian(H, kChi0, kMs);
    Eigen::Matrix3d numeric;
    const double step = 1e-5 * H.norm();
    for (int j = 0; j < 3; ++j) {
      Eigen::Vector3d dh = Eigen::Vector3d::Zero();
      dh(j) = step;
      numeric.col(j) = (mm::froehlich_kennelly(Eigen::Vector3d(H + dh), kChi0, kMs) -
                        mm::froehlich_kennelly(Eigen::Vector3d(H - dh), kChi0, kMs)) /
                       (2.0 * step);
    }
    // Central differences err by O(step^2); the Jacobian is not a multiple of I here (the
    // longitudinal and transverse susceptibilities differ), so this checks its structure.
    EXPECT_LT((analytic - numeric).norm(), 1e-6 * analytic.norm()) << "H = " << H.transpose();
    EXPECT_TRUE(analytic.isApprox(analytic.transpose(), 1e-14));
    // Along H: differential susceptibility; across H: secant susceptibility |M| / |H|.
    const Eigen::Vector3d u = H.normalized();
    EXPECT_NEAR(u.dot(analytic * u), mm::froehlich_kennelly_derivative(H.norm(), kChi0, kMs),
                1e-10 * kChi0);
    const Eigen::Vector3d v = u.unitOrthogonal();
    EXPECT_NEAR(v.dot(analytic * v), mm::froehlich_kennelly(H.norm(), kChi0, kMs) / H.norm(),
                1e-10 * kChi0);
  }
}

TEST(FroehlichKennellyTest, RejectsInvalidParameters) {
  EXPECT_THROW(mm::froehlich_kennelly(1.0, -1.0, kMs), std::invalid_argument);
  EXPECT_THROW(mm::froehlich_kennelly(1.0, kChi0, 0.0), std::invalid_argument);
  EXPECT_THROW(mm::froehlich_kennelly_loop(kChi0, kMs, 1.0, 0.0), std::invalid_argument);
}

TEST(MagnetismLinearSaturableTest, LinearBelowSaturation) {
  const double chi = 3.0;
  const double ms = 1e6;
  const Eigen::Vector3d H(1e5, -2e5, 0.5e5);  // chi |H| = 6.9e5 < Ms
  EXPECT_TRUE(mm::linear_saturable(H, chi, ms).isApprox(chi * H, 1e-15));
  EXPECT_DOUBLE_EQ(mm::linear_saturable(-2e5, chi, ms), -6e5);
  EXPECT_TRUE(
      mm::linear_saturable_jacobian(H, chi, ms).isApprox(chi * Eigen::Matrix3d::Identity(), 1e-15));
}

TEST(MagnetismLinearSaturableTest, ClipsMagnitudeToMsKeepingDirection) {
  const double chi = 3.0;
  const double ms = 1e6;
  const Eigen::Vector3d H(4e5, 3e5, -1.2e5);  // chi |H| = 1.56e6 > Ms
  const Eigen::Vector3d m = mm::linear_saturable(H, chi, ms);
  EXPECT_NEAR(m.norm(), ms, 1e-9 * ms);
  EXPECT_TRUE(m.normalized().isApprox(H.normalized(), 1e-14));
  EXPECT_DOUBLE_EQ(mm::linear_saturable(1e6, chi, ms), ms);
  EXPECT_DOUBLE_EQ(mm::linear_saturable(-1e6, chi, ms), -ms);
  // Exactly at the kink chi |H| = Ms both branches give Ms.
  EXPECT_DOUBLE_EQ(mm::linear_saturable(ms / chi, chi, ms), ms);
  // Saturated Jacobian: zero along H, Ms / |H| across it; compare with finite differences.
  const Eigen::Matrix3d analytic = mm::linear_saturable_jacobian(H, chi, ms);
  EXPECT_NEAR((analytic * H.normalized()).norm(), 0.0, 1e-12);
  Eigen::Matrix3d numeric;
  const double step = 1.0;  // A/m, far from the kink
  for (int j = 0; j < 3; ++j) {
    Eigen::Vector3d dh = Eigen::Vector3d::Zero();
    dh(j) = step;
    numeric.col(j) = (mm::linear_saturable(Eigen::Vector3d(H + dh), chi, ms) -
                      mm::linear_saturable(Eigen::Vector3d(H - dh), chi, ms)) /
                     (2.0 * step);
  }
  EXPECT_LT((analytic - numeric).norm(), 1e-6 * analytic.norm());
}

TEST(FroehlichKennellyTest, LoopHasNoHysteresisAndMatchesClosedFormAtOneTesla) {
  const double b_max = 1.5;
  const mm::MagnetizationCurve curve = mm::froehlich_kennelly_loop(kChi0, kMs, b_max, 0.01);
  ASSERT_EQ(curve.b_tesla.size(), 5u * 150u + 1u);
  ASSERT_EQ(curve.m_over_ms.size(), curve.b_tesla.size());
  ASSERT_EQ(curve.branch.size(), curve.b_tesla.size());

  // Closed form of eq. 1.5 at B = mu0 H = 1 T: M/Ms = chi0 H / (Ms + chi0 H) = 0.97208...
  const double h_one = 1.0 / mresim::kMu0;
  const double expected = kChi0 * h_one / (kMs + kChi0 * h_one);
  EXPECT_NEAR(expected, 0.9721, 1e-4);
  int hits_at_one = 0;
  for (std::size_t i = 0; i < curve.b_tesla.size(); ++i) {
    if (std::abs(curve.b_tesla[i] - 1.0) < 1e-12) {
      EXPECT_NEAR(curve.m_over_ms[i], expected, 1e-12);
      ++hits_at_one;
    }
  }
  EXPECT_EQ(hits_at_one, 3);  // once on each branch

  // Branches coincide: every field on the descending and final ascending branches gives the
  // same M/Ms as on the other branches and as -M/Ms(-B) (odd response).
  std::array<int, 3> per_branch = {0, 0, 0};
  for (std::size_t i = 0; i < curve.b_tesla.size(); ++i) {
    ++per_branch.at(static_cast<std::size_t>(curve.branch[i]));
    for (std::size_t j = 0; j < curve.b_tesla.size(); ++j) {
      if (curve.branch[j] == curve.branch[i]) continue;
      if (std::abs(curve.b_tesla[j] - curve.b_tesla[i]) < 1e-12) {
        EXPECT_NEAR(curve.m_over_ms[j], curve.m_over_ms[i], 1e-14);
      } else if (std::abs(curve.b_tesla[j] + curve.b_tesla[i]) < 1e-12) {
        EXPECT_NEAR(curve.m_over_ms[j], -curve.m_over_ms[i], 1e-14);
      }
    }
  }
  EXPECT_EQ(per_branch[0], 151);
  EXPECT_EQ(per_branch[1], 300);
  EXPECT_EQ(per_branch[2], 300);
  EXPECT_GT(curve.m_over_ms.back(), 0.98);  // B = 1.5 T: nearly saturated, Fig. 1.6

  // No remanence and no coercivity.
  const mm::LoopFeatures features = mm::loop_features(curve);
  EXPECT_NEAR(features.remanence, 0.0, 1e-12);
  EXPECT_NEAR(features.coercive_field_t, 0.0, 1e-12);
}
