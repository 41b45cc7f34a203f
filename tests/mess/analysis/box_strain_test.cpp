// Tests of the box strain and the magnetostriction measure (src/mresim/mess/analysis/
// box_strain.hpp): an imposed affine deformation x -> F X + t gives e_a = F_aa - 1 exactly
// (to rounding), shears and translations give zero, a deformation of one face only moves its
// mean, and the strain along a direction is sum d_a^2 e_a.

#include "mresim/mess/analysis/box_strain.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "../support/mess_test_support.hpp"

namespace ma = mresim::mess_analysis;
namespace mt = mresim::mess::testing;

namespace {

const mresim::lattice::Lattice& box() {
  // An uneven box with a particle, so that the faces are not all alike.
  static const mresim::lattice::Lattice lattice =
      mt::small_lattice(mresim::mess::model_profile("physical"), {5, 6, 7}, {{2, 2, 3}});
  return lattice;
}

Eigen::Matrix3Xd affine(const Eigen::Matrix3Xd& x, const Eigen::Matrix3d& f,
                        const Eigen::Vector3d& t) {
  return (f * x).colwise() + t;
}

}  // namespace

TEST(MessBoxStrain, InitialLatticeIsUnstrained) {
  const Eigen::Vector3d e = ma::box_strain(box(), box().positions);
  EXPECT_EQ(e, Eigen::Vector3d::Zero());
}

TEST(MessBoxStrain, AffineStretchGivesTheDiagonalOfF) {
  Eigen::Matrix3d f = Eigen::Matrix3d::Identity();
  f.diagonal() << 1.0 + 3e-3, 1.0 - 1.25e-3, 1.0 - 7e-4;
  const Eigen::Vector3d e =
      ma::box_strain(box(), affine(box().positions, f, Eigen::Vector3d(1e-6, -2e-6, 5e-7)));
  for (int a = 0; a < 3; ++a) EXPECT_NEAR(e(a), f(a, a) - 1.0, 1e-14) << "axis " << a;
}

TEST(MessBoxStrain, GeneralAffineMapMeasuresOnlyTheDiagonal) {
  // Off-diagonal terms (shear, rotation-like parts) cancel on the symmetric faces.
  Eigen::Matrix3d f;
  f << 1.002, 0.03, -0.01,  //
      0.02, 0.999, 0.015,   //
      -0.04, 0.025, 1.004;
  const Eigen::Vector3d e =
      ma::box_strain(box(), affine(box().positions, f, Eigen::Vector3d::Zero()));
  for (int a = 0; a < 3; ++a) EXPECT_NEAR(e(a), f(a, a) - 1.0, 1e-14) << "axis " << a;
}

TEST(MessBoxStrain, SimpleShearAndTranslationGiveZero) {
  Eigen::Matrix3d f = Eigen::Matrix3d::Identity();
  f(0, 2) = 0.1;  // u_x = 0.1 z, the shear of a strain run
  const Eigen::Vector3d e =
      ma::box_strain(box(), affine(box().positions, f, Eigen::Vector3d(3e-6, 0, 0)));
  EXPECT_NEAR(e.norm(), 0.0, 1e-14);
}

TEST(MessBoxStrain, TopFaceDownIsNegativeZStrain) {
  // Only the top face (z max) moves down by 1 % of the height: e_z = -0.01, the others 0.
  Eigen::Matrix3Xd x = box().positions;
  const double height = box().box_lengths().z();
  for (const int n : mresim::lattice::face_nodes(box().shape, mresim::lattice::Face::top)) {
    x(2, n) -= 0.01 * height;
  }
  const Eigen::Vector3d e = ma::box_strain(box(), x);
  EXPECT_NEAR(e.z(), -0.01, 1e-14);
  // The edges of the side faces moved too, but symmetrically in x and y: their means along x
  // and y do not change.
  EXPECT_NEAR(e.x(), 0.0, 1e-15);
  EXPECT_NEAR(e.y(), 0.0, 1e-15);
}

TEST(MessBoxStrain, StrainAlongADirection) {
  const Eigen::Vector3d e(1e-3, -2e-3, 4e-3);
  EXPECT_DOUBLE_EQ(ma::strain_along(e, Eigen::Vector3d::UnitZ()), 4e-3);
  EXPECT_DOUBLE_EQ(ma::strain_along(e, Eigen::Vector3d::UnitX()), 1e-3);
  const Eigen::Vector3d d = Eigen::Vector3d(1.0, 0.0, 1.0).normalized();
  EXPECT_NEAR(ma::strain_along(e, d), 0.5 * (1e-3 + 4e-3), 1e-18);
  // For an affine stretch the strain along d of the box (its diagonal) is d.(F - I)d.
  Eigen::Matrix3d f = Eigen::Matrix3d::Identity();
  f.diagonal() << 1.001, 1.0005, 0.998;
  const Eigen::Vector3d measured =
      ma::box_strain(box(), affine(box().positions, f, Eigen::Vector3d::Zero()));
  EXPECT_NEAR(ma::strain_along(measured, d), d.dot((f - Eigen::Matrix3d::Identity()) * d), 1e-14);
}

TEST(MessBoxStrain, NonFiniteFaceGivesNaN) {
  Eigen::Matrix3Xd x = box().positions;
  x(0, mresim::lattice::face_nodes(box().shape, mresim::lattice::Face::right).front()) = NAN;
  const Eigen::Vector3d e = ma::box_strain(box(), x);
  EXPECT_TRUE(std::isnan(e.x()));
  EXPECT_EQ(e.z(), 0.0);
}

TEST(MessBoxStrain, WrongNodeCountThrows) {
  EXPECT_THROW((void)ma::box_strain(box(), Eigen::Matrix3Xd(3, 4)), std::invalid_argument);
}
