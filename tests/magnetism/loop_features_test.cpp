// Tests of the major-loop sweep and of the generic coercive-field / remanence extraction.

#include "mresim/magnetism/loop_features.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>
#include <stdexcept>

#include "mresim/magnetism/magnetization_curve.hpp"

namespace mm = mresim::magnetism;

TEST(MagnetizationSweepTest, VisitsZeroPlusMinusPlusOnExactGrid) {
  // 1.0 / 0.3 -> n = 4 steps of 0.25 T (the step is shortened, never lengthened).
  const auto sweep = mm::major_loop_sweep(1.0, 0.3);
  const double expected_b[] = {0,     0.25,  0.5,   0.75, 1,      // branch 0
                               0.75,  0.5,   0.25,  0,    -0.25,  // branch 1
                               -0.5,  -0.75, -1,                  //
                               -0.75, -0.5,  -0.25, 0,    0.25,   // branch 2
                               0.5,   0.75,  1};
  const int expected_branch[] = {0, 0, 0, 0, 0, 1, 1, 1, 1, 1, 1, 1, 1, 2, 2, 2, 2, 2, 2, 2, 2};
  ASSERT_EQ(sweep.size(), 21u);  // 5 n + 1
  for (std::size_t i = 0; i < sweep.size(); ++i) {
    EXPECT_DOUBLE_EQ(sweep[i].b_tesla, expected_b[i]) << i;
    EXPECT_EQ(sweep[i].branch, expected_branch[i]) << i;
  }
  EXPECT_THROW(mm::major_loop_sweep(-1.0, 0.1), std::invalid_argument);
  EXPECT_THROW(mm::major_loop_sweep(1.0, 0.0), std::invalid_argument);
}

TEST(MagnetizationSweepTest, BranchesAndTurningPoints) {
  const auto sweep = mm::major_loop_sweep(1.5, 0.01);  // 1.5 / 0.01 rounds to 150 steps
  ASSERT_EQ(sweep.size(), 751u);
  EXPECT_DOUBLE_EQ(sweep[0].b_tesla, 0.0);
  EXPECT_DOUBLE_EQ(sweep[150].b_tesla, 1.5);
  EXPECT_EQ(sweep[150].branch, mm::kBranchInitialUp);
  EXPECT_EQ(sweep[151].branch, mm::kBranchDown);
  EXPECT_DOUBLE_EQ(sweep[300].b_tesla, 0.0);
  EXPECT_DOUBLE_EQ(sweep[450].b_tesla, -1.5);
  EXPECT_EQ(sweep[450].branch, mm::kBranchDown);
  EXPECT_EQ(sweep[451].branch, mm::kBranchUp);
  EXPECT_DOUBLE_EQ(sweep[600].b_tesla, 0.0);
  EXPECT_DOUBLE_EQ(sweep[750].b_tesla, 1.5);
  for (std::size_t i = 1; i < sweep.size(); ++i) {
    const double step = sweep[i].b_tesla - sweep[i - 1].b_tesla;
    EXPECT_NEAR(std::abs(step), 0.01, 1e-12);
    EXPECT_EQ(step > 0, sweep[i].branch != mm::kBranchDown);
  }
  // Exactly symmetric grid: B on the descending branch is minus B on the ascending branch.
  for (std::size_t j = 0; j < 300; ++j) {
    EXPECT_EQ(sweep[151 + j].b_tesla, -sweep[451 + j].b_tesla);
  }
}

TEST(MagnetizationLoopFeaturesTest, InterpolatesOnDescendingBranchOnly) {
  mm::MagnetizationCurve curve;
  // Initial branch with its own (wrong) zero crossings that must be ignored.
  curve.b_tesla = {0.0, 0.5, 1.0, 0.5, -0.25, -0.75, -1.0, -0.2, 0.6, 1.0};
  curve.m_over_ms = {0.3, -0.1, 1.0, 0.8, 0.2, -0.4, -1.0, -0.7, 0.5, 1.0};
  curve.branch = {0, 0, 0, 1, 1, 1, 1, 2, 2, 2};
  const mm::LoopFeatures features = mm::loop_features(curve);
  // B = 0 between (0.5, 0.8) and (-0.25, 0.2): M = 0.8 - 0.6 * (0.5 / 0.75) = 0.4.
  EXPECT_NEAR(features.remanence, 0.4, 1e-15);
  // M = 0 between (-0.25, 0.2) and (-0.75, -0.4): B = -0.25 - 0.5 * (0.2 / 0.6).
  EXPECT_NEAR(features.coercive_field_t, 0.25 + 0.5 / 3.0, 1e-15);
}

TEST(MagnetizationLoopFeaturesTest, UsesSegmentFromTurningPoint) {
  // The descending branch's first sample is already below B = 0 and M = 0: the crossing lies
  // on the segment from the turning point (last sample of branch 0).
  mm::MagnetizationCurve curve;
  curve.b_tesla = {0.0, 1.0, -1.0};
  curve.m_over_ms = {0.0, 1.0, -0.5};
  curve.branch = {0, 0, 1};
  const mm::LoopFeatures features = mm::loop_features(curve);
  EXPECT_NEAR(features.remanence, 0.25, 1e-15);
  EXPECT_NEAR(features.coercive_field_t, 1.0 / 3.0, 1e-15);  // crossing at B = -1/3
}

TEST(MagnetizationLoopFeaturesTest, RejectsMalformedCurves) {
  mm::MagnetizationCurve curve;
  curve.b_tesla = {0.0, 1.0};
  curve.m_over_ms = {0.0};
  curve.branch = {0, 1};
  EXPECT_THROW(mm::loop_features(curve), std::invalid_argument);
  curve.m_over_ms = {0.5, 0.6};  // never crosses B = 0 or M = 0 descending
  EXPECT_THROW(mm::loop_features(curve), std::invalid_argument);
}
