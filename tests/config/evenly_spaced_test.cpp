#include "mresim/config/evenly_spaced.hpp"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <string>

namespace mresim::config {
namespace {

TEST(EvenlySpaced, TwoPlansGiveTheSameDoubleForTheSameDecimal) {
  // 3 x 0.025 / 5 is 0.015000000000000003 in raw double arithmetic, 3 x 0.04 / 8 is 0.015.
  const double raw = 0.025 * 3.0 / 5.0;
  ASSERT_NE(raw, 0.015) << "the case this rounding exists for";
  const auto short_plan = evenly_spaced_from_zero(0.025, 5);
  const auto long_plan = evenly_spaced_from_zero(0.04, 8);
  EXPECT_EQ(short_plan[3], 0.015);
  EXPECT_EQ(long_plan[3], 0.015);
  for (std::size_t i = 0; i < short_plan.size(); ++i) {
    EXPECT_EQ(short_plan[i], long_plan[i]) << "value " << i;
  }
}

TEST(EvenlySpaced, EveryValueIsTheDecimalAUserWouldType) {
  // 0, 5, ..., 60 mT: each value is exactly the double of the literal k * 0.005.
  const auto values = evenly_spaced_from_zero(0.06, 12);
  ASSERT_EQ(values.size(), 13U);
  for (int k = 0; k <= 12; ++k) {
    const std::string literal = fmt::format("{:.3f}", 0.005 * k);
    EXPECT_EQ(values[static_cast<std::size_t>(k)], std::strtod(literal.c_str(), nullptr))
        << literal;
  }
}

TEST(EvenlySpaced, StartsAtZeroEndsAtMaxAndStaysWithinRoundingOfTheRawProduct) {
  for (const double max : {0.06, -0.1, 1.0 / 3.0, 0.123456789012345678, 2e-7}) {
    for (const long steps : {1L, 7L, 12L, 1000L}) {
      const auto values = evenly_spaced_from_zero(max, steps);
      ASSERT_EQ(values.size(), static_cast<std::size_t>(steps) + 1);
      EXPECT_EQ(values.front(), 0.0);
      EXPECT_EQ(values.back(), max);
      for (long i = 0; i <= steps; ++i) {
        const double raw = max * static_cast<double>(i) / static_cast<double>(steps);
        EXPECT_LE(std::abs(values[static_cast<std::size_t>(i)] - raw), 1e-14 * std::abs(max))
            << "max " << max << ", steps " << steps << ", i " << i;
      }
    }
  }
}

}  // namespace
}  // namespace mresim::config
