#include "mresim/config/range.hpp"

#include <gtest/gtest.h>

#include <limits>

namespace mresim::config {
namespace {

TEST(Range, ContainsRespectsInclusiveness) {
  EXPECT_FALSE(Range::positive().contains(0.0));
  EXPECT_TRUE(Range::positive().contains(1e-300));
  EXPECT_TRUE(Range::non_negative().contains(0.0));
  EXPECT_FALSE(Range::non_negative().contains(-1e-300));
  EXPECT_TRUE(Range::between(0, 90).contains(0));
  EXPECT_TRUE(Range::between(0, 90).contains(90));
  EXPECT_FALSE(Range::between(0, 90).contains(90.0001));
  EXPECT_FALSE(Range::open(0, 1).contains(0));
  EXPECT_FALSE(Range::open(0, 1).contains(1));
  EXPECT_TRUE(Range::open(0, 1).contains(0.5));
  EXPECT_TRUE(Range::at_least(2).contains(2));
  EXPECT_FALSE(Range::above(2).contains(2));
  EXPECT_TRUE(Range::at_most(2).contains(2));
  EXPECT_FALSE(Range::below(2).contains(2));
  EXPECT_TRUE(Range::any().contains(-1e308));
}

TEST(Range, RejectsNaNWhateverTheBounds) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(Range::any().contains(nan));
  EXPECT_FALSE(Range::between(0, 1).contains(nan));
}

TEST(Range, DescribesItself) {
  EXPECT_EQ(Range::positive().describe(), "must be > 0");
  EXPECT_EQ(Range::non_negative().describe(), "must be >= 0");
  EXPECT_EQ(Range::at_least(1e-6).describe(), "must be >= 1e-06");
  EXPECT_EQ(Range::above(2.5).describe(), "must be > 2.5");
  EXPECT_EQ(Range::at_most(3).describe(), "must be <= 3");
  EXPECT_EQ(Range::below(3).describe(), "must be < 3");
  EXPECT_EQ(Range::between(0, 90).describe(), "must be in [0, 90]");
  EXPECT_EQ(Range::open(-1, 0.5).describe(), "must be in (-1, 0.5)");
  EXPECT_EQ(Range::any().describe(), "may be any number");
  const Range half_open{0.0, 1.0, true, false};
  EXPECT_EQ(half_open.describe(), "must be in [0, 1)");
}

}  // namespace
}  // namespace mresim::config
