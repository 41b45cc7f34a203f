// Tests of the magnetic energy terms of the 3D model (Section 4.2.4, eqs. 4.70-4.80): each
// term's gradient with respect to the particle centres against finite differences (also near
// and inside contact), the WCA values and its accuracy at the cut-off, and the envelope
// theorem: with the self-consistent M and the self-energy of eq. 4.76 the derivative of the
// total magnetic energy, re-solving M at every displaced position, is the partial gradient
// at fixed M.

#include "mresim/mess/terms/magnetic_energy.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <numbers>
#include <stdexcept>

#include "../../support/dissertation_values.hpp"
#include "../support/dissertation_particles.hpp"
#include "../support/finite_differences.hpp"
#include "../support/mess_test_support.hpp"
#include "mresim/core/constants.hpp"
#include "mresim/mess/magnetization/self_consistent.hpp"

namespace mm = mresim::magnetism;

namespace {

using mresim::mess::testing::centres_in_radii;
using mresim::mess::testing::kParticles;  // R = 1.5 um, chi0 = 70, Ms = 1.6e6 A/m
using mresim::mess::testing::tesla;
using mresim::testing::kMs;
using mresim::testing::kR;

// Arbitrary (not self-consistent) magnetizations below Ms.
Eigen::Matrix3Xd magnetizations_below_ms(Eigen::Index n) {
  Eigen::Matrix3Xd M(3, n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const double t = static_cast<double>(i);
    M.col(i) = kMs * Eigen::Vector3d(0.3 * std::cos(t), -0.2 + 0.1 * t, 0.5 * std::sin(t + 1.0));
  }
  return M;
}

// Central differences over all 3N coordinates (the shared helper of tests/mess/support).
Eigen::Matrix3Xd numeric_gradient(const std::function<double(const Eigen::Matrix3Xd&)>& energy,
                                  const Eigen::Matrix3Xd& c, double step) {
  return mresim::mess::testing::central_difference_gradient(energy, c, step);
}

// Spread-out, near-contact (gaps 0.03-0.2 R, inside the WCA range) and overlapping (2.0 R
// < r_min = 2.067 R) configurations.
using mresim::mess::testing::kLoose;
const Eigen::Matrix3Xd kNear =
    centres_in_radii({{0.0, 0.0, 0.0}, {2.1, 0.2, -0.1}, {0.5, 2.08, 0.6}, {2.4, 1.9, 1.2}});
const Eigen::Matrix3Xd kPressed =
    centres_in_radii({{0.0, 0.0, 0.0}, {0.3, 0.1, 1.98}, {1.9, 0.4, 0.9}});

struct Configuration {
  const char* name;
  const Eigen::Matrix3Xd* centres;
};
const Configuration kConfigurations[] = {
    {"loose", &kLoose}, {"near contact", &kNear}, {"overlapping", &kPressed}};

mm::MagneticModel model_at(const Eigen::Vector3d& H, double wca_ms = 0.0) {
  return mm::MagneticModel::make(kParticles, H, wca_ms);
}

double relative(const Eigen::Matrix3Xd& a, const Eigen::Matrix3Xd& b) {
  return (a - b).norm() / std::max(b.norm(), 1e-300);
}

}  // namespace

TEST(ParticleMagneticEnergy, DipoleGradientMatchesFiniteDifferences) {
  const mm::MagneticModel model = model_at(tesla(0.0, 0.0, 0.1));
  for (const Configuration& k : kConfigurations) {
    const Eigen::Matrix3Xd M = magnetizations_below_ms(k.centres->cols());
    const auto energy = [&](const Eigen::Matrix3Xd& c) { return mm::dipole_energy(model, c, M); };
    const Eigen::Matrix3Xd analytic = mm::dipole_gradient(model, *k.centres, M);
    EXPECT_LT(relative(numeric_gradient(energy, *k.centres, 1e-5 * kR), analytic), 1e-8) << k.name;
    // Newton's third law: no net force.
    EXPECT_LT(analytic.rowwise().sum().norm(), 1e-12 * analytic.norm()) << k.name;
  }
}

// Eq. 4.78 is minus the gradient of eq. 4.71 (the force on i from j).
TEST(ParticleMagneticEnergy, DipoleGradientIsMinusEq478) {
  const mm::MagneticModel model = model_at(Eigen::Vector3d::Zero());
  const Eigen::Matrix3Xd c = centres_in_radii({{0.0, 0.0, 0.0}, {1.1, -2.0, 0.9}});
  const Eigen::Matrix3Xd M = magnetizations_below_ms(2);
  const double V = kParticles.volume();
  const Eigen::Vector3d mi = V * M.col(0), mj = V * M.col(1);
  const Eigen::Vector3d r = c.col(0) - c.col(1);
  const double s = r.norm();
  const Eigen::Vector3d F = 3.0 * mresim::kMu0 / (4.0 * std::numbers::pi * std::pow(s, 5)) *
                            (mi.dot(r) * mj + mj.dot(r) * mi + mi.dot(mj) * r -
                             5.0 * mi.dot(r) * mj.dot(r) / (s * s) * r);
  const Eigen::Matrix3Xd g = mm::dipole_gradient(model, c, M);
  EXPECT_TRUE((-g.col(0)).isApprox(F, 1e-13));
  EXPECT_TRUE(g.col(1).isApprox(F, 1e-13));
  // Eq. 4.71: -(mu0/2) sum_i m_i . H_dip,i.
  const Eigen::Matrix3Xd H = mm::dipole_fields(c, M, V);
  const double expected =
      -0.5 * mresim::kMu0 * V * (M.col(0).dot(H.col(0)) + M.col(1).dot(H.col(1)));
  EXPECT_NEAR(mm::dipole_energy(model, c, M), expected, 1e-13 * std::abs(expected));
}

TEST(ParticleMagneticEnergy, WcaGradientMatchesFiniteDifferences) {
  for (const double wca_ms : {0.0, 1.9e6}) {  // physical and seed scale
    const mm::MagneticModel model = model_at(Eigen::Vector3d::Zero(), wca_ms);
    for (const Configuration& k : kConfigurations) {
      const auto energy = [&](const Eigen::Matrix3Xd& c) { return mm::wca_energy(model, c); };
      const Eigen::Matrix3Xd analytic = mm::wca_gradient(model, *k.centres);
      const Eigen::Matrix3Xd numeric = numeric_gradient(energy, *k.centres, 1e-6 * kR);
      if (k.centres == &kLoose) {
        EXPECT_EQ(analytic.norm(), 0.0);
        EXPECT_EQ(mm::wca_energy(model, kLoose), 0.0);
        continue;
      }
      EXPECT_GT(analytic.norm(), 0.0) << k.name;
      EXPECT_LT(relative(numeric, analytic), 1e-7) << k.name;
    }
  }
}

TEST(ParticleMagneticEnergy, WcaValuesFollowEq479) {
  // E_max = mu0 pi Ms^2 R^3 / 72; the seed profile scales with 1.9e6 A/m whatever the run's Ms.
  const mm::WcaParameters seed = mm::WcaParameters::from_radius(kR, 1.9e6);
  const double e_seed = mresim::kMu0 * std::numbers::pi * 1.9e6 * 1.9e6 * std::pow(kR, 3) / 72.0;
  EXPECT_NEAR(seed.e_max, e_seed, 1e-15 * e_seed);
  EXPECT_NEAR(seed.e_max, 6.6805e-13, 1e-17);  // J, for R = 1.5 um
  EXPECT_NEAR(seed.r_min, 3.1e-6, 1e-18);
  EXPECT_NEAR(seed.r_cut(), std::pow(2.0, 1.0 / 6.0) * 3.1e-6, 1e-18);
  const mm::MagneticModel physical = model_at(Eigen::Vector3d::Zero());
  EXPECT_NEAR(physical.wca.e_max / seed.e_max, std::pow(1.6 / 1.9, 2), 1e-14);

  const mm::WcaParameters& w = physical.wca;
  // E(r_min) = E_max, dE/dS(r_min) = -24 E_max / r_min (eq. 4.80 with 6 r_min^6 / S^7).
  EXPECT_NEAR(mm::wca_pair(w, w.r_min).energy, w.e_max, 1e-13 * w.e_max);
  EXPECT_NEAR(mm::wca_pair(w, w.r_min).derivative, -24.0 * w.e_max / w.r_min,
              1e-12 * w.e_max / w.r_min);
  // Textbook forms of eqs. 4.79, 4.80 wherever they are accurate.
  for (const double s_over : {0.9, 0.97, 1.0, 1.05, 1.1}) {
    const double s = s_over * w.r_min;
    const double q = w.r_min / s;
    const double e = 4.0 * w.e_max * (std::pow(q, 12) - std::pow(q, 6) + 0.25);
    const double f = 4.0 * w.e_max * (12.0 * std::pow(q, 12) / s - 6.0 * std::pow(q, 6) / s);
    EXPECT_NEAR(mm::wca_pair(w, s).energy, e, 1e-12 * w.e_max) << s_over;
    EXPECT_NEAR(-mm::wca_pair(w, s).derivative, f, 1e-12 * w.e_max / w.r_min) << s_over;
  }
  // Zero at and beyond the cut-off.
  EXPECT_EQ(mm::wca_pair(w, w.r_cut()).energy, 0.0);
  EXPECT_EQ(mm::wca_pair(w, 1.5 * w.r_cut()).derivative, 0.0);
}

// Just inside the cut-off the energy is ~1e-20 E_max; the factored form keeps its relative
// accuracy there (reference: E_max expm1(-6 log1p((S - r_cut)/r_cut))^2), where the printed
// sum q^12 - q^6 + 1/4 returns rounding noise.
TEST(ParticleMagneticEnergy, WcaIsAccurateAtTheCutOff) {
  const mm::WcaParameters w = mm::WcaParameters::from_radius(kR, kMs);
  for (const double gap : {1e-4, 1e-7, 1e-10}) {
    const double s = w.r_cut() * (1.0 - gap);
    const double wr = std::expm1(-6.0 * std::log1p((s - w.r_cut()) / w.r_cut()));
    const double reference = w.e_max * wr * wr;
    EXPECT_NEAR(mm::wca_pair(w, s).energy, reference, 1e-9 * reference) << gap;
    const double derivative = -12.0 * w.e_max * wr * (1.0 + wr) / s;
    EXPECT_NEAR(mm::wca_pair(w, s).derivative, derivative, 1e-9 * std::abs(derivative)) << gap;
  }
}

// Zeeman (uniform field) and both self-energies do not depend on the centres at fixed M.
TEST(ParticleMagneticEnergy, ZeemanAndSelfEnergyHaveNoPositionalGradient) {
  for (const mm::SelfEnergyForm form :
       {mm::SelfEnergyForm::consistent, mm::SelfEnergyForm::linearized}) {
    mm::MagneticModel model = model_at(tesla(0.1, -0.2, 0.3));
    model.self_energy = form;
    for (const Configuration& k : kConfigurations) {
      const Eigen::Matrix3Xd M = magnetizations_below_ms(k.centres->cols());
      const auto zeeman = [&](const Eigen::Matrix3Xd& c) { return mm::zeeman_energy(model, c, M); };
      const auto self = [&](const Eigen::Matrix3Xd& c) { return mm::self_energy(model, c, M); };
      EXPECT_EQ(numeric_gradient(zeeman, *k.centres, 1e-5 * kR).norm(), 0.0);
      EXPECT_EQ(numeric_gradient(self, *k.centres, 1e-5 * kR).norm(), 0.0);
      EXPECT_EQ(mm::zeeman_gradient(model, *k.centres, M).norm(), 0.0);
      EXPECT_EQ(mm::self_energy_gradient(model, *k.centres, M).norm(), 0.0);
    }
  }
}

TEST(ParticleMagneticEnergy, ZeemanAndSelfEnergyValues) {
  const Eigen::Vector3d H = tesla(0.1, -0.2, 0.3);
  mm::MagneticModel model = model_at(H);
  const Eigen::Matrix3Xd M = magnetizations_below_ms(3);
  const Eigen::Matrix3Xd c = kPressed;
  const double V = kParticles.volume();
  const double chi = kParticles.chi0;
  double zeeman = 0.0, self476 = 0.0, self473 = 0.0;
  for (int i = 0; i < 3; ++i) {
    const Eigen::Vector3d moment = V * M.col(i);
    zeeman += -mresim::kMu0 * moment.dot(H);  // eq. 4.70
    const double a = M.col(i).norm();
    self476 += mresim::kMu0 * kMs * V / chi * (-a + kMs * std::log(kMs / (kMs - a)));  // 4.76
    self473 += mresim::kMu0 * moment.squaredNorm() / (2.0 * chi * V * kMs) *
               (kMs + chi * H.norm());  // eq. 4.73
  }
  EXPECT_NEAR(mm::zeeman_energy(model, c, M), zeeman, 1e-13 * std::abs(zeeman));
  EXPECT_NEAR(mm::self_energy(model, c, M), self476, 1e-12 * self476);
  model.self_energy = mm::SelfEnergyForm::linearized;
  EXPECT_NEAR(mm::self_energy(model, c, M), self473, 1e-13 * self473);
  // Demagnetization adds mu0 V |M|^2 / 6 per particle to either form.
  model.demagnetization = true;
  const double demag = mresim::kMu0 * V * M.colwise().squaredNorm().sum() / 6.0;
  EXPECT_NEAR(mm::self_energy(model, c, M), self473 + demag, 1e-13 * self473);
}

namespace {

// Total magnetic energy as a function of the centres alone: M re-solved at every position
// (from the base solution as history, so every evaluation stays on the same branch).
struct Relaxed {
  mm::MagneticModel model;
  mm::MagnetizationOptions options;
  Eigen::Matrix3Xd history;

  Eigen::Matrix3Xd solve(const Eigen::Matrix3Xd& c) const {
    const mm::MagnetizationResult r =
        mm::solve_magnetization(c, model.particles, model.applied_field, history, options);
    EXPECT_TRUE(r.converged);
    return r.M;
  }
  double energy(const Eigen::Matrix3Xd& c) const {
    return mm::magnetic_energies(model, c, solve(c)).total();
  }
};

Relaxed relaxed(const Eigen::Matrix3Xd& c, const mm::MagneticModel& model,
                mm::MagnetizationOptions options) {
  options.demagnetization = model.demagnetization;
  Relaxed r{model, options, Eigen::Matrix3Xd()};
  mm::MagnetizationOptions sharp = options;
  sharp.atol = 1e-13;
  sharp.rtol = 0.0;
  r.history =
      mm::solve_magnetization(c, model.particles, model.applied_field, Eigen::Matrix3Xd(), sharp).M;
  return r;
}

mm::MagnetizationOptions tight_to_1e13() {
  mm::MagnetizationOptions o;
  o.atol = 1e-13;
  o.rtol = 0.0;
  return o;
}

}  // namespace

TEST(ParticleMagneticEnergy, EnvelopeTheoremWithTheConsistentSelfEnergy) {
  struct Case {
    const char* name;
    const Eigen::Matrix3Xd* centres;
    Eigen::Vector3d field;
    bool demagnetization;
  };
  const Case cases[] = {{"loose, 0.1 T", &kLoose, tesla(0.02, -0.03, 0.1), false},
                        {"loose, 1 T", &kLoose, tesla(0.5, 0.0, 0.9), false},
                        {"near contact, 50 mT", &kNear, tesla(0.0, 0.03, 0.04), false},
                        {"overlapping, 0.3 T", &kPressed, tesla(0.1, 0.0, 0.3), false},
                        {"near contact, demagnetized", &kNear, tesla(0.0, 0.03, 0.04), true}};
  for (const Case& k : cases) {
    mm::MagneticModel model = model_at(k.field);
    model.demagnetization = k.demagnetization;
    const Relaxed e = relaxed(*k.centres, model, tight_to_1e13());
    const Eigen::Matrix3Xd partial = mm::magnetic_gradient(model, *k.centres, e.history);
    const Eigen::Matrix3Xd total = numeric_gradient(
        [&](const Eigen::Matrix3Xd& c) { return e.energy(c); }, *k.centres, 1e-5 * kR);
    EXPECT_LT(relative(total, partial), 1e-7) << k.name;
  }
}

// With the dissertation's tolerances (atol 1e-3, rtol 5e-3) the agreement is to that order:
// M's error enters the energy only quadratically, because the energy is stationary in M.
TEST(ParticleMagneticEnergy, EnvelopeTheoremAtTheDissertationsTolerance) {
  const mm::MagneticModel model = model_at(tesla(0.0, 0.03, 0.04));
  const Relaxed e = relaxed(kNear, model, mm::MagnetizationOptions::original());
  const Eigen::Matrix3Xd partial = mm::magnetic_gradient(model, kNear, e.history);
  const Eigen::Matrix3Xd total =
      numeric_gradient([&](const Eigen::Matrix3Xd& c) { return e.energy(c); }, kNear, 1e-3 * kR);
  EXPECT_LT(relative(total, partial), 1e-3);
}

// The fallback chain's states are just as much energy minima: the theorem holds on the
// near-contact triple that the plain fixed point cannot solve.
TEST(ParticleMagneticEnergy, EnvelopeTheoremOnTheFallbackTriple) {
  const Eigen::Matrix3Xd triple =
      centres_in_radii({{0.0, 0.0, 0.0}, {-1.39, 0.04, -1.73}, {-2.79, -0.10, -0.15}});
  const mm::MagneticModel model = model_at(tesla(-0.036, -0.043, -0.045));
  const Relaxed e = relaxed(triple, model, tight_to_1e13());
  const Eigen::Matrix3Xd partial = mm::magnetic_gradient(model, triple, e.history);
  const Eigen::Matrix3Xd total =
      numeric_gradient([&](const Eigen::Matrix3Xd& c) { return e.energy(c); }, triple, 1e-5 * kR);
  EXPECT_LT(relative(total, partial), 1e-7);
}

// Eq. 4.73 is not stationary in M, so the energy it reports is not the potential of the
// dipole forces: the same check fails by far more than the solver tolerance.
TEST(ParticleMagneticEnergy, LinearizedSelfEnergyIsNotThePotentialOfTheForces) {
  mm::MagneticModel model = model_at(tesla(0.0, 0.03, 0.04));
  model.self_energy = mm::SelfEnergyForm::linearized;
  const Relaxed e = relaxed(kNear, model, tight_to_1e13());
  const Eigen::Matrix3Xd partial = mm::magnetic_gradient(model, kNear, e.history);
  const Eigen::Matrix3Xd total =
      numeric_gradient([&](const Eigen::Matrix3Xd& c) { return e.energy(c); }, kNear, 1e-5 * kR);
  EXPECT_GT(relative(total, partial), 0.05);
}

TEST(ParticleMagneticEnergy, BreakdownAndShapeChecks) {
  const mm::MagneticModel model = model_at(tesla(0.0, 0.0, 0.2));
  const Eigen::Matrix3Xd M = magnetizations_below_ms(4);
  const mm::MagneticEnergyBreakdown e = mm::magnetic_energies(model, kNear, M);
  EXPECT_DOUBLE_EQ(e.total(), e.zeeman + e.dipole + e.self + e.wca);
  EXPECT_DOUBLE_EQ(e.dipole, mm::dipole_energy(model, kNear, M));
  EXPECT_DOUBLE_EQ(e.wca, mm::wca_energy(model, kNear));
  EXPECT_GT(e.wca, 0.0);
  EXPECT_TRUE(mm::magnetic_gradient(model, kNear, M)
                  .isApprox(mm::dipole_gradient(model, kNear, M) + mm::wca_gradient(model, kNear)));
  EXPECT_THROW((void)mm::dipole_energy(model, kNear, magnetizations_below_ms(3)),
               std::invalid_argument);
  EXPECT_THROW((void)mm::WcaParameters::from_radius(kR, -1.0), std::invalid_argument);
  EXPECT_THROW((void)mm::dipole_gradient(model, mm::PairList{{0, 5, Eigen::Vector3d::Ones()}}, M),
               std::invalid_argument);
  // A saturated particle has infinite eq. 4.76 self-energy.
  Eigen::Matrix3Xd saturated = M;
  saturated.col(0) = Eigen::Vector3d(0.0, 0.0, kMs);
  EXPECT_TRUE(std::isinf(mm::self_energy(model, kNear, saturated)));
}
