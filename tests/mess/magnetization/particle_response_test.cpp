// Tests of the single-particle law of the 3D model: eq. 4.55 (Froehlich-Kennelly), its
// demagnetized variant m = FK(h - m/3), their inverses, Jacobians and the self-energy eq. 4.76
// whose gradient is the inverse law.

#include "mresim/mess/magnetization/particle_response.hpp"

#include <gtest/gtest.h>

#include <Eigen/LU>
#include <cmath>

#include "../../support/dissertation_values.hpp"
#include "mresim/core/constants.hpp"
#include "mresim/magnetism/froehlich_kennelly.hpp"

namespace mm = mresim::magnetism;

namespace {

using mresim::testing::kMs;

constexpr double kChi = 70.0;

// Fields from 1e-6 to 1e3 Ms in a few directions.
std::vector<Eigen::Vector3d> sample_fields() {
  std::vector<Eigen::Vector3d> fields;
  const Eigen::Vector3d dirs[] = {{0.0, 0.0, 1.0},
                                  Eigen::Vector3d(0.3, -0.8, 0.5).normalized(),
                                  Eigen::Vector3d(-1.0, 0.2, 0.1).normalized()};
  for (const auto& d : dirs) {
    for (double h = 1e-6; h < 2e3; h *= 7.3) fields.push_back(h * d);
  }
  return fields;
}

Eigen::Matrix3d numeric_jacobian(const auto& f, const Eigen::Vector3d& x, double step) {
  Eigen::Matrix3d J;
  for (int k = 0; k < 3; ++k) {
    Eigen::Vector3d p = x, m = x;
    p(k) += step;
    m(k) -= step;
    J.col(k) = (f(p) - f(m)) / (2.0 * step);
  }
  return J;
}

}  // namespace

TEST(ParticleResponse, WithoutDemagnetizationIsEq455) {
  for (const Eigen::Vector3d& h : sample_fields()) {
    const Eigen::Vector3d expected = mm::froehlich_kennelly(Eigen::Vector3d(h * kMs), kChi, kMs);
    EXPECT_TRUE(mm::particle_response(h, kChi, false).isApprox(expected / kMs, 1e-14));
    EXPECT_TRUE(
        mm::particle_response_jacobian(h, kChi, false)
            .isApprox(mm::froehlich_kennelly_jacobian(Eigen::Vector3d(h * kMs), kChi, kMs), 1e-13));
  }
}

TEST(ParticleResponse, DemagnetizedLawSolvesFkOfTheInternalField) {
  for (const Eigen::Vector3d& h : sample_fields()) {
    const Eigen::Vector3d m = mm::particle_response(h, kChi, true);
    const Eigen::Vector3d internal = h - m / 3.0;
    const Eigen::Vector3d fk = mm::particle_response(internal, kChi, false);
    EXPECT_LT((m - fk).norm(), 1e-14 * (1.0 + m.norm())) << h.transpose();
    EXPECT_LT(m.norm(), 1.0);
    EXPECT_GE(internal.dot(h), 0.0);  // the internal field is never reversed
  }
}

TEST(ParticleResponse, DemagnetizedWeakFieldSusceptibilityIsChiOverOnePlusChiOverThree) {
  const Eigen::Vector3d h(0.0, 1e-9, 0.0);
  const double apparent = kChi / (1.0 + kChi / 3.0);  // 2.877 for chi = 70
  EXPECT_NEAR(mm::particle_response(h, kChi, true).y() / h.y(), apparent, apparent * 1e-7);
  EXPECT_TRUE(mm::particle_response_jacobian(Eigen::Vector3d::Zero(), kChi, true)
                  .isApprox(apparent * Eigen::Matrix3d::Identity(), 1e-15));
  // Saturates all the same: |m| -> 1 at large fields.
  EXPECT_NEAR(mm::particle_response(Eigen::Vector3d(0.0, 0.0, 1e4), kChi, true).z(), 1.0, 1e-3);
}

TEST(ParticleResponse, JacobiansMatchFiniteDifferences) {
  for (const bool demag : {false, true}) {
    for (const Eigen::Vector3d& h : sample_fields()) {
      if (h.norm() < 1e-4) continue;  // the kink of |h| at 0 is below any useful step
      const double step = 1e-6 * h.norm();
      const auto f = [&](const Eigen::Vector3d& x) {
        return mm::particle_response(x, kChi, demag);
      };
      const Eigen::Matrix3d analytic = mm::particle_response_jacobian(h, kChi, demag);
      EXPECT_LT((analytic - numeric_jacobian(f, h, step)).norm(), 1e-7 * analytic.norm())
          << "demag " << demag << " h " << h.transpose();
    }
  }
}

TEST(ParticleResponse, InverseLawAndItsJacobianInvertTheLaw) {
  for (const bool demag : {false, true}) {
    for (const Eigen::Vector3d& h : sample_fields()) {
      if (h.norm() > 1e2) continue;  // |m| within 1e-4 of 1: the inverse is ill-conditioned
      const Eigen::Vector3d m = mm::particle_response(h, kChi, demag);
      EXPECT_LT((mm::particle_response_inverse(m, kChi, demag) - h).norm(), 1e-10 * h.norm());
      const Eigen::Matrix3d product = mm::particle_response_inverse_jacobian(m, kChi, demag) *
                                      mm::particle_response_jacobian(h, kChi, demag);
      EXPECT_TRUE(product.isApprox(Eigen::Matrix3d::Identity(), 1e-9)) << product;
    }
  }
  // Saturation is never reached at a finite field.
  EXPECT_FALSE(
      mm::particle_response_inverse(Eigen::Vector3d(0.0, 0.0, 1.0), kChi, false).allFinite());
  EXPECT_TRUE(std::isinf(mm::reduced_self_energy(Eigen::Vector3d(1.0, 0.0, 0.0), kChi, false)));
}

// Eq. 4.76 written as printed, in SI, equals mu0 Ms^2 V times the reduced self-energy, and
// its gradient over m is the inverse law (so minimising self - m.h gives the law).
TEST(ParticleResponse, SelfEnergyIsEq476AndItsGradientIsTheInverseLaw) {
  const double V = 1.4137e-17;
  for (const double a : {1e-3, 0.2, 0.7, 0.99}) {
    const double M = a * kMs;
    const double printed =
        mresim::kMu0 * kMs * V / kChi * (-M + kMs * std::log(kMs / (kMs - M)));  // eq. 4.76
    const Eigen::Vector3d m = a * Eigen::Vector3d(0.6, 0.0, 0.8);
    EXPECT_NEAR(mresim::kMu0 * kMs * kMs * V * mm::reduced_self_energy(m, kChi, false), printed,
                1e-9 * printed);
  }
  for (const bool demag : {false, true}) {
    for (const Eigen::Vector3d& m :
         {Eigen::Vector3d(0.01, 0.02, -0.03), Eigen::Vector3d(0.3, -0.2, 0.5),
          Eigen::Vector3d(0.0, 0.0, 0.97)}) {
      Eigen::Vector3d numeric;
      const double step = 1e-7;
      for (int k = 0; k < 3; ++k) {
        Eigen::Vector3d p = m, q = m;
        p(k) += step;
        q(k) -= step;
        numeric(k) =
            (mm::reduced_self_energy(p, kChi, demag) - mm::reduced_self_energy(q, kChi, demag)) /
            (2.0 * step);
      }
      const Eigen::Vector3d analytic = mm::particle_response_inverse(m, kChi, demag);
      EXPECT_LT((numeric - analytic).norm(), 1e-6 * analytic.norm()) << m.transpose();
    }
  }
}
