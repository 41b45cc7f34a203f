// Tests of the point-dipole field of eq. 4.57 between the particles of the 3D model, and of
// the pair-list (displacement policy) design that periodic images will plug into.

#include "mresim/mess/magnetization/dipole_field.hpp"

#include <gtest/gtest.h>

#include <numbers>
#include <stdexcept>

#include "../../support/dissertation_values.hpp"

namespace mm = mresim::magnetism;

namespace {

using mresim::testing::kR;

const double kV = 4.0 / 3.0 * std::numbers::pi * kR * kR * kR;

// Eq. 4.57 exactly as printed.
Eigen::Vector3d eq_4_57(const Eigen::Vector3d& r_ij, const Eigen::Vector3d& M_j, double V) {
  const double r = r_ij.norm();
  const Eigen::Vector3d n = r_ij / r;
  return V / (4.0 * std::numbers::pi) * (3.0 * n * M_j.dot(n) - M_j) / (r * r * r);
}

Eigen::Matrix3Xd scattered_centres() {
  Eigen::Matrix3Xd c(3, 5);
  c << 0.0, 2.2, -1.0, 3.1, 0.4,  //
      0.0, 0.3, 2.5, -2.0, 1.1,   //
      0.0, -0.5, 0.7, 1.9, -2.6;
  return c * kR;
}

Eigen::Matrix3Xd some_magnetizations(int n) {
  Eigen::Matrix3Xd M(3, n);
  for (int i = 0; i < n; ++i) M.col(i) = 1e5 * Eigen::Vector3d(1.0 + i, -0.5 * i, 2.0 - i);
  return M;
}

}  // namespace

TEST(ParticleDipoleField, TensorIsEq457) {
  const Eigen::Vector3d r(1.3e-6, -2.0e-6, 0.7e-6);
  const Eigen::Vector3d M(3e5, 1e5, -8e5);
  EXPECT_TRUE((mm::dipole_tensor(r, kV) * M).isApprox(eq_4_57(r, M, kV), 1e-14));
  const Eigen::Matrix3d D = mm::dipole_tensor(r, kV);
  EXPECT_TRUE(D.isApprox(D.transpose(), 1e-15));
  EXPECT_NEAR(D.trace(), 0.0, 1e-15 * D.norm());
  EXPECT_TRUE(D.isApprox(mm::dipole_tensor(-r, kV), 1e-15));  // even in r
}

TEST(ParticleDipoleField, AxialAndTransverseFieldsOfTouchingSpheres) {
  // At contact (r = 2R) the coupling is V/(4 pi r^3) = 1/24: +2/24 along the bond, -1/24
  // across it (the numbers behind the zero-field instability and the oscillating iteration).
  const Eigen::Vector3d r(0.0, 0.0, 2.0 * kR);
  const Eigen::Matrix3d D = mm::dipole_tensor(r, kV);
  EXPECT_NEAR(D(2, 2), 2.0 / 24.0, 1e-15);
  EXPECT_NEAR(D(0, 0), -1.0 / 24.0, 1e-15);
  EXPECT_NEAR(D(1, 1), -1.0 / 24.0, 1e-15);
}

TEST(ParticleDipoleField, CouplingFieldIsTheSumOverAllOtherParticles) {
  const Eigen::Matrix3Xd c = scattered_centres();
  const Eigen::Matrix3Xd M = some_magnetizations(static_cast<int>(c.cols()));
  const Eigen::Matrix3Xd H = mm::dipole_fields(c, M, kV);
  for (int i = 0; i < c.cols(); ++i) {
    Eigen::Vector3d expected = Eigen::Vector3d::Zero();
    for (int j = 0; j < c.cols(); ++j) {
      if (j != i) expected += eq_4_57(c.col(i) - c.col(j), M.col(j), kV);
    }
    EXPECT_TRUE(H.col(i).isApprox(expected, 1e-13)) << i;
  }
  // The dense matrix is the same linear map, and symmetric.
  const mm::DipoleCoupling coupling = mm::DipoleCoupling::open(c, kV);
  EXPECT_EQ(coupling.pairs().size(), 10u);
  const Eigen::MatrixXd A = coupling.dense();
  EXPECT_TRUE(A.isApprox(A.transpose(), 1e-15));
  const Eigen::VectorXd flat = A * Eigen::Map<const Eigen::VectorXd>(M.data(), M.size());
  EXPECT_TRUE(flat.isApprox(Eigen::Map<const Eigen::VectorXd>(H.data(), H.size()), 1e-13));
}

// The contract a periodic policy relies on: an entry (i, i, L) stands for the +-L images of a
// particle and adds 2 D(L) M_i; an entry (i, j, r + L) is one more image of j at i.
TEST(ParticleDipoleField, PairListEntriesForImages) {
  const Eigen::Vector3d L(0.0, 0.0, 7.0 * kR);
  const Eigen::Vector3d r01(2.5 * kR, 0.0, 0.0);
  mm::PairList pairs = {{0, 1, r01}, {0, 1, r01 + L}, {0, 0, L}};
  const mm::DipoleCoupling coupling(2, pairs, kV);
  Eigen::Matrix3Xd M(3, 2);
  M.col(0) = Eigen::Vector3d(1e5, 0.0, 5e5);
  M.col(1) = Eigen::Vector3d(-2e5, 3e5, 4e5);
  const Eigen::Matrix3Xd H = coupling.field(M);
  const Eigen::Vector3d H0 = eq_4_57(r01, M.col(1), kV) + eq_4_57(r01 + L, M.col(1), kV) +
                             eq_4_57(L, M.col(0), kV) + eq_4_57(-L, M.col(0), kV);
  const Eigen::Vector3d H1 = eq_4_57(-r01, M.col(0), kV) + eq_4_57(-r01 - L, M.col(0), kV);
  EXPECT_TRUE(H.col(0).isApprox(H0, 1e-13));
  EXPECT_TRUE(H.col(1).isApprox(H1, 1e-13));
}

TEST(ParticleDipoleField, RejectsCoincidentCentresAndBadIndices) {
  Eigen::Matrix3Xd c = scattered_centres();
  c.col(3) = c.col(1);
  EXPECT_THROW((void)mm::DipoleCoupling::open(c, kV), std::invalid_argument);
  EXPECT_THROW(mm::DipoleCoupling(2, {{0, 2, Eigen::Vector3d(1e-6, 0.0, 0.0)}}, kV),
               std::invalid_argument);
  EXPECT_THROW(mm::DipoleCoupling(2, {}, -1.0), std::invalid_argument);
  const mm::DipoleCoupling coupling = mm::DipoleCoupling::open(scattered_centres(), kV);
  EXPECT_THROW((void)coupling.field(Eigen::Matrix3Xd::Zero(3, 4)), std::invalid_argument);
}
