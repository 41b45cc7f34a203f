#include "mresim/pair/pair_energy.hpp"

#include <gtest/gtest.h>

#include "mresim/pair/overlap_penalty.hpp"
#include "mresim/pair/stiffness.hpp"

namespace mresim::pair {
namespace {

PairSystem three_spring(PenaltyKind kind) {
  PairSystem s;
  const PuljizStiffness k = puljiz_stiffness(1375.0, 1.5e-6, 9e-6);
  s.springs = {SpringModel::three, k.k12, k.k0, 9e-6};
  s.penalty = kind == PenaltyKind::tanh ? OverlapPenalty::tanh_default(1.5e-6)
                                        : OverlapPenalty::wca_default(1.5e-6);
  return s;
}

// Central differences of the scaled energy, with a step suited to the local length scale.
Eigen::Vector3d numeric_gradient(const PairEnergy& e, const Eigen::Vector3d& d, double h) {
  Eigen::Vector3d g;
  for (int i = 0; i < 3; ++i) {
    Eigen::Vector3d p = d;
    Eigen::Vector3d m = d;
    p(i) += h;
    m(i) -= h;
    g(i) = (e.scaled_energy(p) - e.scaled_energy(m)) / (2.0 * h);
  }
  return g;
}

struct GradientCase {
  const char* name;
  PenaltyKind penalty;
  double field_tesla;
  double angle_deg;
  Eigen::Vector3d d;  // units of R
  double step;
};

void PrintTo(const GradientCase& c, std::ostream* os) { *os << c.name; }

class PairEnergyGradient : public ::testing::TestWithParam<GradientCase> {};

// Every term of eq. 2.3/2.4 (Zeeman, dipole, self, springs, penalty) with the relaxed
// magnetization: the analytic gradient equals the finite-difference gradient of the energy.
TEST_P(PairEnergyGradient, MatchesFiniteDifferences) {
  const GradientCase& c = GetParam();
  PairSystem system = three_spring(c.penalty);
  if (c.penalty == PenaltyKind::tanh) system.penalty.delta = 1e5;  // resolvable by differences
  const PairEnergy energy(system, c.field_tesla * field_direction(c.angle_deg));
  const Eigen::Vector3d analytic = energy.scaled_gradient(c.d);
  const Eigen::Vector3d numeric = numeric_gradient(energy, c.d, c.step);
  EXPECT_LT((analytic - numeric).norm(), 1e-7 * (1.0 + analytic.norm()))
      << c.name << "\nanalytic " << analytic.transpose() << "\nnumeric  " << numeric.transpose();
}

INSTANTIATE_TEST_SUITE_P(
    AllRegimes, PairEnergyGradient,
    ::testing::Values(
        GradientCase{"unsaturated, apart", PenaltyKind::wca, 0.2, 30.0, {4.0, 0.3, 1.5}, 1e-6},
        GradientCase{"saturated, apart", PenaltyKind::wca, 1.5, 30.0, {4.0, 0.3, 1.5}, 1e-6},
        GradientCase{"saturated, oblique", PenaltyKind::tanh, 0.9, 70.0, {3.0, -0.2, 2.0}, 1e-6},
        GradientCase{"WCA near contact", PenaltyKind::wca, 0.6, 10.0, {2.0, 0.1, 0.6}, 1e-8},
        GradientCase{"WCA compressed", PenaltyKind::wca, 1.0, 45.0, {1.9, 0.0, 0.5}, 1e-6},
        GradientCase{"tanh near contact", PenaltyKind::tanh, 0.5, 0.0, {2.01, 0.0, 0.05}, 1e-8},
        GradientCase{"zero field", PenaltyKind::wca, 0.0, 0.0, {5.0, 1.0, -0.5}, 1e-6}),
    [](const auto& info) { return "case" + std::to_string(info.index); });

TEST(PairEnergyHessian, MatchesFiniteDifferencesOfTheGradient) {
  for (const Eigen::Vector3d& d :
       {Eigen::Vector3d(4.0, 0.0, 1.0), Eigen::Vector3d(2.1, 0.0, 0.5)}) {
    const PairSystem system = three_spring(PenaltyKind::wca);
    const PairEnergy energy(system, 0.7 * field_direction(20.0));
    const Eigen::Matrix3d analytic = energy.scaled_hessian(d);
    Eigen::Matrix3d numeric;
    const double h = 1e-7;
    for (int i = 0; i < 3; ++i) {
      Eigen::Vector3d p = d;
      Eigen::Vector3d m = d;
      p(i) += h;
      m(i) -= h;
      numeric.col(i) = (energy.scaled_gradient(p) - energy.scaled_gradient(m)) / (2.0 * h);
    }
    EXPECT_LT((analytic - numeric).norm(), 1e-5 * (1.0 + analytic.norm())) << d.transpose();
  }
}

TEST(OverlapPenalty, DerivativesMatchFiniteDifferences) {
  const double r = 1.5e-6;
  OverlapPenalty tanh = OverlapPenalty::tanh_default(r);
  tanh.delta = 1e4;  // the printed 1e-2 1/um: a smooth roll-off that differences can resolve
  const OverlapPenalty wca = OverlapPenalty::wca_default(r);
  for (const auto& [p, s] : {std::pair{tanh, 3.1e-6}, std::pair{tanh, 2.9e-6},
                             std::pair{wca, 3.2e-6}, std::pair{wca, 2.95e-6}}) {
    const double h = 1e-13;
    const PenaltyValue v = overlap_penalty(p, r, s);
    const double d1 =
        (overlap_penalty(p, r, s + h).energy - overlap_penalty(p, r, s - h).energy) / (2 * h);
    const double d2 =
        (overlap_penalty(p, r, s + h).derivative - overlap_penalty(p, r, s - h).derivative) /
        (2 * h);
    EXPECT_NEAR(v.derivative, d1, 1e-6 * std::abs(v.derivative));
    EXPECT_NEAR(v.second_derivative, d2, 1e-5 * std::abs(v.second_derivative));
  }
}

TEST(OverlapPenalty, WcaIsContinuousAtTheCutoffAndZeroBeyond) {
  const OverlapPenalty wca = OverlapPenalty::wca_default(1.5e-6);
  EXPECT_NEAR(overlap_penalty(wca, 1.5e-6, wca.r_cut * (1 - 1e-12)).energy, 0.0, 1e-12);
  EXPECT_EQ(overlap_penalty(wca, 1.5e-6, wca.r_cut * 1.01).energy, 0.0);
  // The text's form 4 E_max((r/S)^12 - (r/S)^6 + 1/4) at contact S = r_min: E_max.
  EXPECT_NEAR(overlap_penalty(wca, 1.5e-6, wca.r_min).energy, wca.e_max, 1e-15);
}

TEST(PairEnergyBreakdown, TermsSumToTheMinimisedEnergyInJoules) {
  const PairSystem system = three_spring(PenaltyKind::wca);
  const PairEnergy energy(system, 0.4 * field_direction(30.0));
  const Eigen::Vector3d d(3.5, 0.0, 1.0);
  const EnergyBreakdown e = energy.breakdown(d);
  EXPECT_NEAR(e.total(), energy.scaled_energy(d) * energy.energy_scale(),
              1e-12 * std::abs(e.total()));
  EXPECT_LT(e.zeeman, 0.0);
  EXPECT_GT(e.self, 0.0);
  EXPECT_GT(e.anchor, 0.0);
}

}  // namespace
}  // namespace mresim::pair
