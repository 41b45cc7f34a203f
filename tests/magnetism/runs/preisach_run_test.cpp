// Tests of the run type "preisach" (Fig. 1.5): run-file reading, `info` values (including the
// analytic expectations of preisach_expectation.hpp) and the outputs.

#include <gtest/gtest.h>

#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "../../support/hdf5_read.hpp"
#include "../../support/run_plan.hpp"
#include "../../support/temp_dir.hpp"
#include "mresim/app/run_type.hpp"
#include "mresim/magnetism/loop_features.hpp"
#include "mresim/magnetism/preisach.hpp"
#include "mresim/magnetism/runs/preisach_expectation.hpp"

namespace mresim::magnetism::runs {
namespace {

using mresim::testing::Hdf5Reader;
using mresim::testing::info_of;
using mresim::testing::info_value;
using mresim::testing::plan_error_of;
using mresim::testing::plan_of;
using mresim::testing::TempDir;

TEST(PreisachRun, DefaultsAreFigure15) {
  const nlohmann::json info = info_of("preisach", "");
  EXPECT_EQ(info["preisach"]["relays"]["value"].get<long>(), 100000);
  EXPECT_DOUBLE_EQ(info_value(info, "preisach", "switch_up_mean"), 0.35);
  EXPECT_DOUBLE_EQ(info_value(info, "preisach", "switch_down_mean"), -0.35);
  EXPECT_DOUBLE_EQ(info_value(info, "preisach", "switch_sd"), 0.2);
  EXPECT_DOUBLE_EQ(info_value(info, "preisach", "weight_mean"), 5.0);
  EXPECT_DOUBLE_EQ(info_value(info, "preisach", "weight_sd"), 2.5);
  EXPECT_DOUBLE_EQ(info_value(info, "preisach", "weight_min"), 0.01);
  EXPECT_EQ(info["preisach"]["seed"]["value"].get<long>(), 1);
  EXPECT_DOUBLE_EQ(info_value(info, "field", "max"), 1.0);
  EXPECT_EQ(info["field"]["steps_per_branch"]["value"].get<long>(), 100);
  EXPECT_EQ(info["field"]["samples"]["value"].get<long>(), 501);
}

TEST(PreisachRun, DescribesAnalyticCoercivityAndRemanence) {
  const nlohmann::json info = info_of("preisach", "[field]\nmax = 1.5\nstep = 0.01\n");
  EXPECT_EQ(info["field"]["samples"]["value"].get<long>(), 751);
  // Values of tests/magnetism/preisach_test.cpp: B_c = 0.35006 T (0.35 without the swap of
  // alpha < beta draws), M_r/Ms = 1 - 2 Phi(1.75) (1 - Phi(1.75)) = 0.92313.
  EXPECT_NEAR(info_value(info, "derived", "expected_coercive_field"), 0.35006, 2e-5);
  const double phi = 0.5 * std::erfc(-1.75 / std::sqrt(2.0));
  EXPECT_NEAR(info_value(info, "derived", "expected_remanence"), 1.0 - 2.0 * phi * (1.0 - phi),
              1e-14);
  // At 1.5 T, alpha ~ N(0.35, 0.2) is 5.75 sd below: saturated.
  EXPECT_NEAR(info_value(info, "derived", "expected_up_fraction_at_field_max"), 1.0, 1e-8);
  EXPECT_NEAR(info_value(info, "derived", "sampling_noise"), 1.0 / std::sqrt(1e5), 1e-15);
  // P(N(5, 2.5) < 0.01) = Phi(-1.996) = 0.02297.
  EXPECT_NEAR(info_value(info, "derived", "clipped_weight_fraction"), 0.02297, 1e-5);
}

TEST(PreisachRun, ExpectationFollowsTheSwitchingFieldMeans) {
  // Narrow, well separated distributions: the swap never matters, B_c = -switch_down_mean.
  PreisachParameters p;
  p.switch_up_mean_t = 0.6;
  p.switch_down_mean_t = -0.2;
  p.switch_sd_t = 0.01;
  EXPECT_NEAR(expected_coercive_field(p), 0.2, 1e-12);
  EXPECT_NEAR(expected_remanence(p), 1.0, 1e-12);
  EXPECT_NEAR(expected_descending_branch(p, -0.3), -1.0, 1e-12);
}

TEST(PreisachRun, WritesTheLoopOfPreisachLoop) {
  TempDir dir;
  const auto plan = plan_of(
      "preisach", "[preisach]\nrelays = 20000\nseed = 7\n[field]\nmax = 1.5\nstep = 0.05\n");
  {
    io::Hdf5File results(dir / "results.h5");
    app::Progress progress(0, "test", {nullptr, false, 0.5});
    plan->execute(dir.path(), results, progress);
    EXPECT_EQ(progress.done(), 151U);
    results.close();
  }
  const std::size_t n = 30;
  const std::size_t samples = 5 * n + 1;
  PreisachParameters p;
  p.relay_count = 20000;
  p.seed = 7;
  const MagnetizationCurve reference = preisach_loop(p, 1.5, 0.05);
  ASSERT_EQ(reference.b_tesla.size(), samples);

  const Hdf5Reader h5(dir / "results.h5");
  ASSERT_EQ(h5.shape("/curve/field"), std::vector<hsize_t>{samples});
  ASSERT_EQ(h5.shape("/curve/branch"), std::vector<hsize_t>{samples});
  ASSERT_EQ(h5.shape("/curve/magnetization"), std::vector<hsize_t>{samples});
  EXPECT_EQ(h5.doubles("/curve/field"), reference.b_tesla);
  EXPECT_EQ(h5.doubles("/curve/magnetization"), reference.m_over_ms);  // bitwise: same seed
  const std::vector<std::int64_t> branch = h5.ints("/curve/branch");
  EXPECT_EQ(std::vector<std::int64_t>(reference.branch.begin(), reference.branch.end()), branch);
  EXPECT_NEAR(h5.doubles("/curve/magnetization")[n], 1.0, 1e-12);  // saturated at +1.5 T

  const auto attr = [&](const char* name) {
    return h5.scalar_attribute<double>("/curve", name, H5T_NATIVE_DOUBLE);
  };
  const LoopFeatures features = loop_features(reference);
  EXPECT_EQ(attr("coercive_field_T"), features.coercive_field_t);
  EXPECT_EQ(attr("remanence"), features.remanence);
  // 2e4 relays: sampling noise ~0.01 in M/Ms, ~3e-3 T in B_c; 0.05 T grid interpolation.
  EXPECT_NEAR(attr("coercive_field_T"), 0.35, 0.03);
  EXPECT_NEAR(attr("remanence"), 0.923, 0.04);
  EXPECT_TRUE(std::isnan(attr("saturation_magnetization_A_per_m")));  // normalized model
  EXPECT_FALSE(h5.has_attribute("/curve", "initial_susceptibility"));

  std::istringstream csv(mresim::testing::read_text(dir / "summary.csv"));
  std::string line;
  std::getline(csv, line);
  EXPECT_EQ(line, "step,branch,B_T,M_over_Ms");
  std::size_t rows = 0;
  while (std::getline(csv, line)) ++rows;
  EXPECT_EQ(rows, samples);
}

TEST(PreisachRun, MinorLoopWithoutSwitchingGivesNaNFeatures) {
  // Switching fields around +5 T and +3 T (sd 0.1 T) with a 0.01 T sweep: every relay starts
  // down (beta >= 0) and none ever switches, so the descending branch never crosses M = 0.
  // The run must still succeed, writing NaN for both features.
  TempDir dir;
  const auto plan = plan_of(
      "preisach",
      "[preisach]\nrelays = 1000\nswitch_up_mean = 5\nswitch_down_mean = 3\nswitch_sd = 0.1\n"
      "[field]\nmax = 0.01\nstep = 0.01\n");
  {
    io::Hdf5File results(dir / "results.h5");
    app::Progress progress(0, "test", {nullptr, false, 0.5});
    plan->execute(dir.path(), results, progress);
    results.close();
  }
  const Hdf5Reader h5(dir / "results.h5");
  for (double m : h5.doubles("/curve/magnetization")) EXPECT_NEAR(m, -1.0, 1e-12);
  EXPECT_TRUE(
      std::isnan(h5.scalar_attribute<double>("/curve", "coercive_field_T", H5T_NATIVE_DOUBLE)));
  EXPECT_TRUE(std::isnan(h5.scalar_attribute<double>("/curve", "remanence", H5T_NATIVE_DOUBLE)));
}

TEST(PreisachRun, RejectsInvalidInput) {
  EXPECT_EQ(plan_error_of("preisach", "[preisach]\nrelays = 0\n"),
            "preisach.relays = 0: must be in [1, 100000000]");
  EXPECT_EQ(plan_error_of("preisach", "[preisach]\nrelays = 2.5\n"),
            "preisach.relays = 2.5: expected an integer");
  EXPECT_EQ(plan_error_of("preisach", "[preisach]\nswitch_sd = -0.2\n"),
            "preisach.switch_sd = -0.2: must be > 0 (T)");
  EXPECT_EQ(plan_error_of("preisach", "[preisach]\nswitch_sd = 0\n"),
            "preisach.switch_sd = 0: must be > 0 (T)");
  EXPECT_EQ(plan_error_of("preisach", "[preisach]\nweight_mean = 0\n"),
            "preisach.weight_mean = 0: must be > 0");
  EXPECT_EQ(plan_error_of("preisach", "[preisach]\nweight_sd = -1\n"),
            "preisach.weight_sd = -1: must be >= 0");
  EXPECT_EQ(plan_error_of("preisach", "[preisach]\nweight_min = 0\n"),
            "preisach.weight_min = 0: must be > 0");
  EXPECT_EQ(plan_error_of("preisach", "[preisach]\nseed = -1\n"),
            "preisach.seed = -1: must be >= 0");
  EXPECT_EQ(plan_error_of("preisach", "[preisach]\nseed = 1.0\n"),
            "preisach.seed = 1.0: expected an integer");
  EXPECT_EQ(plan_error_of("preisach", "[preisach]\nswitch_up_mean = \"0.35\"\n"),
            "preisach.switch_up_mean = \"0.35\": expected a number (T)");
  EXPECT_EQ(plan_error_of("preisach", "[preisach]\nrelais = 100\n"),
            "unknown key 'preisach.relais' in [preisach]; allowed keys: relays, seed, "
            "switch_down_mean, switch_sd, switch_up_mean, weight_mean, weight_min, weight_sd");
  EXPECT_EQ(plan_error_of("preisach", "[field]\nstep = 0\n"), "field.step = 0: must be > 0 (T)");
  EXPECT_EQ(plan_error_of("preisach", "[field]\nmax = 1.5\nstep = 0.04\n"),
            "field.max = 1.5: must be a whole number of field.step = 0.04 T (the sweep visits "
            "0, +max, -max exactly)");
  EXPECT_EQ(plan_error_of("preisach", "[material]\nsusceptibility = 70\n"),
            "unknown table [material]; allowed: field, preisach, run");
  EXPECT_EQ(plan_error_of("preisach", "[field]\nmax = 1e308\nstep = 1e302\n"),
            "field.max = 1e+308: must be <= 1e+100 T (H = B / mu0 and the products of eq. 1.5 "
            "must stay finite)");
}

}  // namespace
}  // namespace mresim::magnetism::runs
