// The safety net of the Chapter 1 outputs: a curve with non-finite points (which validation
// should make unreachable from a run file) is written with NaN and reported by step and
// quantity, never published silently.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "../../support/hdf5_read.hpp"
#include "../../support/temp_dir.hpp"
#include "mresim/magnetism/runs/curve_outputs.hpp"

namespace mresim::magnetism::runs {
namespace {

using mresim::testing::Hdf5Reader;
using mresim::testing::TempDir;

MagnetizationCurve small_loop() {
  MagnetizationCurve c;
  c.b_tesla = {0.0, 1.0, 0.0, -1.0, 0.0, 1.0};
  c.m_over_ms = {0.0, 0.9, 0.1, -0.9, -0.1, 0.9};
  c.branch = {0, 0, 1, 1, 2, 2};
  return c;
}

TEST(CurveResultCheck, NonFinitePointsAreFlaggedAndWrittenAsNaN) {
  TempDir dir;
  MagnetizationCurve curve = small_loop();
  curve.m_over_ms[1] = std::numeric_limits<double>::quiet_NaN();
  curve.b_tesla[3] = -std::numeric_limits<double>::infinity();
  app::ResultCheck check("none");
  {
    io::Hdf5File results(dir / "results.h5");
    check = write_curve(dir.path(), results, curve, {1.6e6, 70.0});
    results.close();
  }
  ASSERT_TRUE(check.any());
  const std::string message = check.message("hint");
  EXPECT_EQ(message,
            "non-finite results: M_over_Ms at step 1 (B = 1 T); B_T at step 3; "
            "coercive_field_T and remanence at /curve (from a non-finite curve) (hint)");
  EXPECT_THROW(check.throw_if_any("hint"), app::InvalidResults);
  const Hdf5Reader h5(dir / "results.h5");
  EXPECT_TRUE(std::isnan(h5.doubles("/curve/field")[3]));  // -inf written as NaN
  EXPECT_TRUE(std::isnan(h5.doubles("/curve/magnetization")[1]));
  const std::string csv = mresim::testing::read_text(dir / "summary.csv");
  EXPECT_EQ(csv.find("inf"), std::string::npos) << csv;
}

TEST(CurveResultCheck, FiniteLoopPasses) {
  TempDir dir;
  io::Hdf5File results(dir / "results.h5");
  const app::ResultCheck check = write_curve(dir.path(), results, small_loop(), {1.6e6, 70.0});
  results.close();
  EXPECT_FALSE(check.any()) << check.message("");
}

}  // namespace
}  // namespace mresim::magnetism::runs
