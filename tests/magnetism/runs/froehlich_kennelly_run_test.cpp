// Tests of the run type "froehlich_kennelly" (Fig. 1.6): run-file reading, `info` values and
// the outputs summary.csv / results.h5.

#include <gtest/gtest.h>

#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "../../support/hdf5_read.hpp"
#include "../../support/run_plan.hpp"
#include "../../support/temp_dir.hpp"
#include "mresim/app/run_type.hpp"
#include "mresim/core/constants.hpp"

namespace mresim::magnetism::runs {
namespace {

using mresim::testing::Hdf5Reader;
using mresim::testing::info_of;
using mresim::testing::info_value;
using mresim::testing::plan_error_of;
using mresim::testing::plan_of;
using mresim::testing::TempDir;

// Eq. 1.5 for the applied field B = mu0 H, written out independently of the library.
double fk_m_over_ms(double b, double chi0, double ms) {
  const double h = b / kMu0;
  return chi0 * h / (ms + chi0 * std::abs(h));
}

TEST(FroehlichKennellyRun, DefaultsAreFigure16) {
  const nlohmann::json info = info_of("froehlich_kennelly", "");
  EXPECT_DOUBLE_EQ(info_value(info, "material", "susceptibility"), 70.0);
  EXPECT_DOUBLE_EQ(info_value(info, "material", "saturation_magnetization"), 1.6e6);
  EXPECT_DOUBLE_EQ(info_value(info, "field", "max"), 1.0);
  EXPECT_DOUBLE_EQ(info_value(info, "field", "step"), 0.01);
  EXPECT_EQ(info["field"]["steps_per_branch"]["value"].get<long>(), 100);
  EXPECT_EQ(info["field"]["samples"]["value"].get<long>(), 501);
}

TEST(FroehlichKennellyRun, DescribesDerivedQuantitiesInClosedForm) {
  const nlohmann::json info =
      info_of("froehlich_kennelly",
              "[material]\nsusceptibility = 50\nsaturation_magnetization = 1.2e6\n"
              "[field]\nmax = 0.5\nstep = 0.005\n");
  EXPECT_EQ(info["field"]["steps_per_branch"]["value"].get<long>(), 100);
  EXPECT_EQ(info["field"]["samples"]["value"].get<long>(), 501);
  const double h = 0.5 / kMu0;  // 397887 A/m
  EXPECT_NEAR(info_value(info, "derived", "H_at_field_max"), h, 1e-9 * h);
  EXPECT_NEAR(info_value(info, "derived", "M_over_Ms_at_field_max"), 50 * h / (1.2e6 + 50 * h),
              1e-14);
  // M = Ms/2 at chi0 H = Ms: H = 24000 A/m, B = mu0 H = 0.030159 T.
  EXPECT_NEAR(info_value(info, "derived", "half_saturation_H"), 24000.0, 1e-9);
  EXPECT_NEAR(info_value(info, "derived", "half_saturation_B"), 0.0301593, 1e-7);
  EXPECT_NEAR(fk_m_over_ms(info_value(info, "derived", "half_saturation_B"), 50, 1.2e6), 0.5,
              1e-12);
}

TEST(FroehlichKennellyRun, WritesCurveToCsvAndHdf5) {
  TempDir dir;
  const auto plan = plan_of("froehlich_kennelly", "[field]\nmax = 0.5\nstep = 0.005\n");
  {
    io::Hdf5File results(dir / "results.h5");
    app::Progress progress(0, "test", {nullptr, false, 0.5});
    plan->execute(dir.path(), results, progress);
    results.close();
  }
  const std::size_t n = 100;
  const std::size_t samples = 5 * n + 1;

  // summary.csv: header and one row per field value.
  std::istringstream csv(mresim::testing::read_text(dir / "summary.csv"));
  std::string line;
  std::getline(csv, line);
  EXPECT_EQ(line, "step,branch,B_T,M_over_Ms");
  std::vector<std::string> rows;
  while (std::getline(csv, line)) rows.push_back(line);
  ASSERT_EQ(rows.size(), samples);
  EXPECT_EQ(rows.front(), "0,0,0,0");
  const double m_max = fk_m_over_ms(0.5, 70, 1.6e6);  // 0.9457
  double step = 0;
  double branch = 0;
  double b = 0;
  double m = 0;
  char comma = 0;
  std::istringstream(rows[n]) >> step >> comma >> branch >> comma >> b >> comma >> m;
  EXPECT_EQ(step, 100);
  EXPECT_EQ(branch, 0);
  EXPECT_DOUBLE_EQ(b, 0.5);
  EXPECT_NEAR(m, m_max, 1e-9);  // 10 significant digits in the CSV

  const Hdf5Reader h5(dir / "results.h5");
  const std::vector<double> field = h5.doubles("/curve/field");
  const std::vector<double> mag = h5.doubles("/curve/magnetization");
  const std::vector<std::int64_t> branches = h5.ints("/curve/branch");
  ASSERT_EQ(field.size(), samples);
  ASSERT_EQ(mag.size(), samples);
  ASSERT_EQ(branches.size(), samples);
  EXPECT_EQ(h5.string_attribute("/curve/field", "unit"), "T");
  EXPECT_EQ(h5.string_attribute("/curve/magnetization", "unit"), "1");
  // Turning points: +max ends branch 0, -max ends branch 1, +max ends branch 2.
  EXPECT_DOUBLE_EQ(field[n], 0.5);
  EXPECT_DOUBLE_EQ(field[3 * n], -0.5);
  EXPECT_DOUBLE_EQ(field.back(), 0.5);
  EXPECT_EQ(branches[n], 0);
  EXPECT_EQ(branches[n + 1], 1);
  EXPECT_EQ(branches[3 * n], 1);
  EXPECT_EQ(branches[3 * n + 1], 2);
  EXPECT_NEAR(mag[n], m_max, 1e-14);
  EXPECT_NEAR(mag[3 * n], -m_max, 1e-14);
  EXPECT_NEAR(mag.back(), m_max, 1e-14);
  for (std::size_t i = 0; i < samples; ++i) {
    ASSERT_NEAR(mag[i], fk_m_over_ms(field[i], 70, 1.6e6), 1e-14) << i;
  }
  // Anhysteretic: no coercivity, no remanence (Fig. 1.6 caption).
  const auto attr = [&](const char* name) {
    return h5.scalar_attribute<double>("/curve", name, H5T_NATIVE_DOUBLE);
  };
  EXPECT_EQ(attr("coercive_field_T"), 0.0);
  EXPECT_EQ(attr("remanence"), 0.0);
  EXPECT_EQ(attr("saturation_magnetization_A_per_m"), 1.6e6);
  EXPECT_EQ(attr("initial_susceptibility"), 70.0);
}

TEST(FroehlichKennellyRun, RejectsInvalidInput) {
  EXPECT_EQ(plan_error_of("froehlich_kennelly", "[material]\nsusceptibility = 0\n"),
            "material.susceptibility = 0: must be > 0");
  EXPECT_EQ(plan_error_of("froehlich_kennelly", "[material]\nsusceptibility = -70\n"),
            "material.susceptibility = -70: must be > 0");
  EXPECT_EQ(plan_error_of("froehlich_kennelly", "[material]\nsaturation_magnetization = 0\n"),
            "material.saturation_magnetization = 0: must be > 0 (A/m)");
  EXPECT_EQ(plan_error_of("froehlich_kennelly", "[field]\nstep = 0\n"),
            "field.step = 0: must be > 0 (T)");
  EXPECT_EQ(plan_error_of("froehlich_kennelly", "[field]\nmax = -1\n"),
            "field.max = -1: must be > 0 (T)");
  EXPECT_EQ(plan_error_of("froehlich_kennelly", "[field]\nmax = 0.105\nstep = 0.01\n"),
            "field.max = 0.105: must be a whole number of field.step = 0.01 T (the sweep visits "
            "0, +max, -max exactly)");
  EXPECT_EQ(plan_error_of("froehlich_kennelly", "[field]\nmax = 1.0\nstep = 1e-7\n"),
            "field.step = 1e-07: must give at most 1e6 steps up to field.max");
  EXPECT_EQ(plan_error_of("froehlich_kennelly", "[material]\nsusceptibilty = 70\n"),
            "unknown key 'material.susceptibilty' in [material]; allowed keys: "
            "saturation_magnetization, susceptibility");
  EXPECT_EQ(plan_error_of("froehlich_kennelly", "[material]\nsusceptibility = \"70\"\n"),
            "material.susceptibility = \"70\": expected a number");
  EXPECT_EQ(plan_error_of("froehlich_kennelly", "[preisach]\nrelays = 10\n"),
            "unknown table [preisach]; allowed: field, material, run");
}

// Values whose products in eq. 1.5 (chi0 H Ms, H = B / mu0) overflow: before the fix these ran
// and wrote B_T = inf, M_over_Ms = NaN with only a warning.
TEST(FroehlichKennellyRun, RejectsParametersThatOverflowEquation15) {
  EXPECT_EQ(plan_error_of("froehlich_kennelly", "[field]\nmax = 1e308\nstep = 1e302\n"),
            "field.max = 1e+308: must be <= 1e+100 T (H = B / mu0 and the products of eq. 1.5 "
            "must stay finite)");
  EXPECT_EQ(plan_error_of("froehlich_kennelly", "[material]\nsaturation_magnetization = 1e308\n"),
            "material.saturation_magnetization = 1e+308: must be <= 1e+60 A/m (eq. 1.5 "
            "multiplies chi0 H Ms, which would overflow)");
  EXPECT_EQ(plan_error_of("froehlich_kennelly", "[material]\nsusceptibility = 1e308\n"),
            "material.susceptibility = 1e+308: must be <= 1e+60 (eq. 1.5 multiplies chi0 H Ms, "
            "which would overflow)");
  // The bounds themselves still give a finite curve.
  TempDir dir;
  const auto plan = plan_of("froehlich_kennelly",
                            "[material]\nsusceptibility = 1e60\nsaturation_magnetization = 1e60\n"
                            "[field]\nmax = 1e100\nstep = 1e99\n");
  io::Hdf5File results(dir / "results.h5");
  app::Progress progress(0, "test", {nullptr, false, 0.5});
  EXPECT_NO_THROW(plan->execute(dir.path(), results, progress));
  results.close();
  for (const double m : Hdf5Reader(dir / "results.h5").doubles("/curve/magnetization")) {
    EXPECT_TRUE(std::isfinite(m));
  }
}

TEST(FroehlichKennellyRun, AcceptsStepsThatDivideMaxUpToRounding) {
  // 0.3 / 0.1 = 2.9999999999999996 in binary: still exactly three steps.
  const nlohmann::json info = info_of("froehlich_kennelly", "[field]\nmax = 0.3\nstep = 0.1\n");
  EXPECT_EQ(info["field"]["steps_per_branch"]["value"].get<long>(), 3);
}

}  // namespace
}  // namespace mresim::magnetism::runs
