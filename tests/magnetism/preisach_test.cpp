// Tests of the classical Preisach model of Fig. 1.5 (Section 1.3.3) and its major loop.

#include "mresim/magnetism/preisach.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <numeric>
#include <stdexcept>

#include "mresim/magnetism/loop_features.hpp"

namespace mm = mresim::magnetism;

namespace {

constexpr double kBMax = 1.5;    // T, well beyond all switching fields (0.35 + 5.75 sd)
constexpr double kBStep = 0.01;  // T

// Upper tail of the standard normal distribution.
double upper_tail(double z) { return 0.5 * std::erfc(z / std::sqrt(2.0)); }

// Expected descending branch from positive saturation for the Fig. 1.5 parameters. A relay is
// down at field B iff B <= beta, where beta = min(a, b) after the swap of a ~ N(0.35, 0.2) and
// b ~ N(-0.35, 0.2), and P(min(a, b) >= B) = P(a >= B) P(b >= B). The weights are drawn
// independently of the switching fields, so in expectation
//   M/Ms(B) = 1 - 2 P(a >= B) P(b >= B).
double expected_descending(double b) {
  return 1.0 - 2.0 * upper_tail((b - 0.35) / 0.2) * upper_tail((b + 0.35) / 0.2);
}

// Expected coercive field: the zero of expected_descending, by bisection. Without the swap it
// would be exactly 0.35 T; the swap moves it by ~6e-5 T to 0.35006 T.
double expected_coercive_field() {
  // expected_descending(lo) < 0 < expected_descending(hi)
  double lo = -1.0;
  double hi = 0.0;
  for (int i = 0; i < 100; ++i) {
    const double mid = 0.5 * (lo + hi);
    (expected_descending(mid) > 0.0 ? hi : lo) = mid;
  }
  return -0.5 * (lo + hi);
}

double value_at(const mm::MagnetizationCurve& curve, int branch, double b) {
  for (std::size_t i = 0; i < curve.b_tesla.size(); ++i) {
    if (curve.branch[i] == branch && std::abs(curve.b_tesla[i] - b) < 1e-12) {
      return curve.m_over_ms[i];
    }
  }
  ADD_FAILURE() << "no sample at B = " << b << " on branch " << branch;
  return std::nan("");
}

// The default (Fig. 1.5) loop is used by several tests; compute it once.
const mm::MagnetizationCurve& default_loop() {
  static const mm::MagnetizationCurve curve = mm::preisach_loop({}, kBMax, kBStep);
  return curve;
}

}  // namespace

TEST(PreisachTest, RelayPopulationFollowsParameters) {
  const mm::PreisachModel model(mm::PreisachParameters{});
  ASSERT_EQ(model.relay_count(), 100000u);
  const auto& alpha = model.up_switching_fields_t();
  const auto& beta = model.down_switching_fields_t();
  const auto& w = model.weights();
  double alpha_sum = 0.0;
  double beta_sum = 0.0;
  for (std::size_t i = 0; i < model.relay_count(); ++i) {
    ASSERT_GE(alpha[i], beta[i]);
    alpha_sum += alpha[i];
    beta_sum += beta[i];
  }
  // The swap raises the mean of alpha = max(a, b) by E[max(0, b - a)] ~ 1e-3 T; the sampling
  // standard error of the mean is 0.2 / sqrt(1e5) = 6e-4 T.
  EXPECT_NEAR(alpha_sum / 1e5, 0.35, 0.004);
  EXPECT_NEAR(beta_sum / 1e5, -0.35, 0.004);
  EXPECT_NEAR(std::accumulate(w.begin(), w.end(), 0.0), 1.0, 1e-12);
  // Clipped to 0.01 before normalization by the sum (~5e5): nothing below 0.01 / 6e5.
  EXPECT_GT(*std::min_element(w.begin(), w.end()), 0.01 / 6e5);
  // Clipping is active: N(5, 2.5) falls below 0.01 in ~2.3 % of the draws.
  const double smallest = *std::min_element(w.begin(), w.end());
  const auto clipped = std::count(w.begin(), w.end(), smallest);
  EXPECT_GT(clipped, 1500);
  EXPECT_LT(clipped, 3000);
}

TEST(PreisachTest, FirstRelaysMatchIndependentReference) {
  // Per relay: alpha, beta, weight from one mt19937_64(seed) stream through Box-Muller; the
  // reference normals come from an independent Python implementation (seed 1).
  mm::PreisachParameters params;
  params.relay_count = 2;
  const mm::PreisachModel model(params);
  EXPECT_NEAR(model.up_switching_fields_t()[0], 0.35 + 0.2 * 1.312851528985561, 1e-13);
  EXPECT_NEAR(model.down_switching_fields_t()[0], -0.35 + 0.2 * 1.5159465040060633, 1e-13);
  EXPECT_NEAR(model.up_switching_fields_t()[1], 0.35 + 0.2 * 0.1661713810523931, 1e-13);
  EXPECT_NEAR(model.down_switching_fields_t()[1], -0.35 + 0.2 * 1.2285219999610568, 1e-13);
  const double w0 = 5.0 + 2.5 * 1.2506039211781215;
  const double w1 = 5.0 + 2.5 * -0.7650179338846085;
  EXPECT_NEAR(model.weights()[0], w0 / (w0 + w1), 1e-13);
  EXPECT_NEAR(model.weights()[1], w1 / (w0 + w1), 1e-13);
}

TEST(PreisachTest, SwapsThresholdsDrawnInWrongOrder) {
  // Mean thresholds reversed: nearly every draw has a < b and must be swapped.
  mm::PreisachParameters params;
  params.relay_count = 1000;
  params.switch_up_mean_t = -0.5;
  params.switch_down_mean_t = 0.5;
  params.switch_sd_t = 0.05;
  const mm::PreisachModel model(params);
  for (std::size_t i = 0; i < model.relay_count(); ++i) {
    ASSERT_GE(model.up_switching_fields_t()[i], model.down_switching_fields_t()[i]);
    EXPECT_GT(model.up_switching_fields_t()[i], 0.2);  // the former b ~ N(0.5, 0.05)
  }
}

TEST(PreisachTest, SameSeedGivesIdenticalCurve) {
  mm::PreisachParameters params;
  params.relay_count = 20000;
  params.seed = 12345;
  const mm::MagnetizationCurve a = mm::preisach_loop(params, kBMax, kBStep);
  const mm::MagnetizationCurve b = mm::preisach_loop(params, kBMax, kBStep);
  EXPECT_EQ(a.b_tesla, b.b_tesla);
  EXPECT_EQ(a.m_over_ms, b.m_over_ms);  // bitwise
  EXPECT_EQ(a.branch, b.branch);
}

TEST(PreisachTest, DifferentSeedGivesDifferentCurveWithSameShape) {
  mm::PreisachParameters params;
  params.relay_count = 20000;
  params.seed = 2;
  const mm::MagnetizationCurve other = mm::preisach_loop(params, kBMax, kBStep);
  params.seed = 3;
  const mm::MagnetizationCurve third = mm::preisach_loop(params, kBMax, kBStep);
  ASSERT_EQ(other.m_over_ms.size(), third.m_over_ms.size());
  int differing = 0;
  for (std::size_t i = 0; i < other.m_over_ms.size(); ++i) {
    if (std::abs(other.m_over_ms[i] - third.m_over_ms[i]) > 1e-9) ++differing;
  }
  // Only the saturated ends (|B| >~ 1.1 T) can agree; the switching region differs.
  EXPECT_GT(differing, 300);
  // Statistically the same loop: features agree within sampling noise (~2e-3 T, ~3e-3).
  const mm::LoopFeatures f2 = mm::loop_features(other);
  const mm::LoopFeatures f3 = mm::loop_features(third);
  EXPECT_NEAR(f2.coercive_field_t, f3.coercive_field_t, 0.02);
  EXPECT_NEAR(f2.remanence, f3.remanence, 0.02);
}

TEST(PreisachTest, InitialStateIsDemagnetizedAndBalanced) {
  const mm::PreisachModel model(mm::PreisachParameters{});
  const auto& w = model.weights();
  const double max_weight = *std::max_element(w.begin(), w.end());
  // The balancing rule bounds |M/Ms| by the largest weight (~3e-5 here).
  EXPECT_LE(std::abs(model.magnetization()), max_weight);
  EXPECT_LT(std::abs(model.magnetization()), 1e-3);
  EXPECT_EQ(default_loop().b_tesla.front(), 0.0);
  EXPECT_LT(std::abs(default_loop().m_over_ms.front()), 0.01);
  EXPECT_EQ(default_loop().m_over_ms.front(), model.magnetization());

  // Forced relays are in the zero-field state; bistable ones are mixed about half and half.
  int bistable = 0;
  int bistable_up = 0;
  for (std::size_t i = 0; i < model.relay_count(); ++i) {
    const double a = model.up_switching_fields_t()[i];
    const double b = model.down_switching_fields_t()[i];
    const signed char s = model.states()[i];  // +1 up, -1 down
    if (a <= 0.0) {
      EXPECT_EQ(s, 1);
    } else if (b >= 0.0) {
      EXPECT_EQ(s, -1);
    } else {
      ++bistable;
      bistable_up += s > 0 ? 1 : 0;
    }
  }
  // P(b < 0 < a) = Phi(1.75)^2 = 0.92 of the relays.
  EXPECT_NEAR(bistable / 1e5, 0.92, 0.01);
  EXPECT_NEAR(static_cast<double>(bistable_up) / bistable, 0.5, 0.05);
}

TEST(PreisachTest, SaturatesAtPlusMinusOneAtOnePointFiveTesla) {
  const mm::MagnetizationCurve& curve = default_loop();
  EXPECT_NEAR(value_at(curve, mm::kBranchInitialUp, kBMax), 1.0, 1e-12);
  EXPECT_NEAR(value_at(curve, mm::kBranchDown, -kBMax), -1.0, 1e-12);
  EXPECT_NEAR(curve.m_over_ms.back(), 1.0, 1e-12);
  // ...but not yet at 0.5 T: there the initial curve is at ~P(alpha <= 0.5) - P(beta >= 0) ~ 0.73.
  EXPECT_LT(value_at(curve, mm::kBranchInitialUp, 0.5), 0.9);
  for (double m : curve.m_over_ms) {
    EXPECT_LE(m, 1.0 + 1e-12);
    EXPECT_GE(m, -1.0 - 1e-12);
  }
}

TEST(PreisachTest, MajorLoopIsHystereticWithExpectedCoercivityAndRemanence) {
  const mm::MagnetizationCurve& curve = default_loop();
  const mm::LoopFeatures features = mm::loop_features(curve);

  // Analytic expectation (see expected_descending): B_c = 0.35006 T and
  // M_r/Ms = 1 - 2 Phi(1.75) (1 - Phi(1.75)) = 0.9231. Sampling noise with 1e5 relays is
  // ~0.0035 in M/Ms, i.e. ~1e-3 T in B_c (slope dM/dB = 4 / T at B_c); the linear
  // interpolation error on the 0.01 T grid is < 1e-4 T. The bounds are ~10 sigma.
  const double bc = expected_coercive_field();
  EXPECT_NEAR(bc, 0.35006, 2e-5);
  EXPECT_NEAR(features.coercive_field_t, bc, 0.01);
  const double remanence = expected_descending(0.0);
  EXPECT_NEAR(remanence, 0.9231, 1e-4);
  EXPECT_NEAR(features.remanence, remanence, 0.01);
  EXPECT_GT(features.remanence, 0.5);

  // The whole descending branch follows the threshold distribution.
  for (int k = -8; k <= 8; ++k) {  // B = -0.8 ... 0.8 T (an integer counter: exact end)
    const double b = 0.1 * k;
    EXPECT_NEAR(value_at(curve, mm::kBranchDown, b), expected_descending(b), 0.01) << b;
  }

  // Hysteresis: the branches differ by ~2 M_r at B = 0, and the final ascending branch is the
  // mirror image of the descending one (relays have mirror-symmetric distributions).
  EXPECT_GT(value_at(curve, mm::kBranchDown, 0.0) - value_at(curve, mm::kBranchUp, 0.0), 1.5);
  for (int k = -8; k <= 8; ++k) {
    const double b = 0.1 * k;
    EXPECT_NEAR(value_at(curve, mm::kBranchUp, b), -expected_descending(-b), 0.01) << b;
  }
}

TEST(PreisachTest, InitialCurveLiesInsideMajorLoop) {
  // Relay by relay, the state on the initial curve is between the states on the ascending
  // and descending branches at the same field, so the sums are ordered exactly.
  const mm::MagnetizationCurve& curve = default_loop();
  for (int k = 1; k < 150; ++k) {
    const double b = kBMax * k / 150.0;
    const double initial = value_at(curve, mm::kBranchInitialUp, b);
    EXPECT_LE(initial, value_at(curve, mm::kBranchDown, b) + 1e-12) << b;
    EXPECT_GE(initial, value_at(curve, mm::kBranchUp, b) - 1e-12) << b;
  }
  // And strictly inside where the loop is open, e.g. at 0.3 T.
  EXPECT_LT(value_at(curve, mm::kBranchInitialUp, 0.3),
            value_at(curve, mm::kBranchDown, 0.3) - 0.3);
  EXPECT_GT(value_at(curve, mm::kBranchInitialUp, 0.3), value_at(curve, mm::kBranchUp, 0.3) + 0.3);
}

TEST(PreisachTest, RejectsInvalidParameters) {
  mm::PreisachParameters params;
  params.relay_count = 0;
  EXPECT_THROW(mm::PreisachModel{params}, std::invalid_argument);
  params = {};
  params.weight_min = 0.0;
  EXPECT_THROW(mm::PreisachModel{params}, std::invalid_argument);
  params = {};
  params.switch_sd_t = -0.1;
  EXPECT_THROW(mm::PreisachModel{params}, std::invalid_argument);
}
