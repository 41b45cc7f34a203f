// Tests of the closest pair's orientation (src/mresim/mess/analysis/pair_orientation.hpp): the
// closest of several pairs, the angle against the axis for known geometries (along, across,
// 30 degrees, tiny tilts), independence of the pair's order, NaN without a pair.

#include "mresim/mess/analysis/pair_orientation.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace ma = mresim::mess_analysis;

namespace {

Eigen::Matrix3Xd pair(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  Eigen::Matrix3Xd c(3, 2);
  c.col(0) = a;
  c.col(1) = b;
  return c;
}

const Eigen::Vector3d kZ = Eigen::Vector3d::UnitZ();

}  // namespace

TEST(MessPairOrientation, ClosestOfThree) {
  Eigen::Matrix3Xd c(3, 3);
  c.col(0) << 0.0, 0.0, 0.0;
  c.col(1) << 10e-6, 0.0, 0.0;
  c.col(2) << 10e-6, 0.0, 4e-6;  // 1-2: 4 um, the closest
  const ma::ClosestPair p = ma::closest_pair(c);
  EXPECT_EQ(p.first, 1);
  EXPECT_EQ(p.second, 2);
  EXPECT_DOUBLE_EQ(p.distance, 4e-6);
  EXPECT_DOUBLE_EQ(ma::pair_angle(c, kZ), 0.0);  // along z
  EXPECT_DOUBLE_EQ(ma::pair_angle(c, Eigen::Vector3d::UnitX()), std::numbers::pi / 2);
}

TEST(MessPairOrientation, KnownAnglesAndOrderIndependence) {
  const double s = 6e-6;
  const double theta = std::numbers::pi / 6;  // 30 degrees from z, in the x-z plane
  const Eigen::Vector3d a(5e-6, 5e-6, 5e-6);
  const Eigen::Vector3d b = a + s * Eigen::Vector3d(std::sin(theta), 0.0, std::cos(theta));
  EXPECT_NEAR(ma::pair_angle(pair(a, b), kZ), theta, 1e-15);
  EXPECT_NEAR(ma::pair_angle(pair(b, a), kZ), theta, 1e-15);   // r and -r alike
  EXPECT_NEAR(ma::pair_angle(pair(a, b), -kZ), theta, 1e-15);  // the axis' sign neither
  // Against the x axis the same pair is 60 degrees off.
  EXPECT_NEAR(ma::pair_angle(pair(a, b), Eigen::Vector3d::UnitX()), std::numbers::pi / 3, 1e-15);
}

TEST(MessPairOrientation, TinyTiltIsResolved) {
  // A pair tilted by 1e-9 rad: cos(1e-9) rounds to 1, the angle must not.
  const double tilt = 1e-9;
  const Eigen::Vector3d a = Eigen::Vector3d::Zero();
  const Eigen::Vector3d b = 6e-6 * Eigen::Vector3d(std::sin(tilt), 0.0, std::cos(tilt));
  EXPECT_NEAR(ma::pair_angle(pair(a, b), kZ), tilt, 1e-15);
}

TEST(MessPairOrientation, NoPairGivesNaN) {
  EXPECT_TRUE(std::isnan(ma::pair_angle(Eigen::Matrix3Xd(3, 0), kZ)));
  EXPECT_TRUE(std::isnan(ma::pair_angle(Eigen::Matrix3Xd::Zero(3, 1), kZ)));
  EXPECT_EQ(ma::closest_pair(Eigen::Matrix3Xd::Zero(3, 1)).first, -1);
  Eigen::Matrix3Xd c = pair(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ());
  c(0, 1) = NAN;
  EXPECT_TRUE(std::isnan(ma::pair_angle(c, kZ)));
}
