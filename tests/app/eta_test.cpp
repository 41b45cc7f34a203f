// EtaEstimator (eta.hpp): the weighted time per unit and the time left.

#include "mresim/app/eta.hpp"

#include <gtest/gtest.h>

namespace mresim::app {
namespace {

TEST(Eta, UnknownBeforeTheFirstUnit) {
  EtaEstimator eta;
  eta.start(0.0, 0);
  EXPECT_FALSE(eta.remaining(5.0, 10).has_value());
  EXPECT_FALSE(eta.seconds_per_unit().has_value());
}

TEST(Eta, WeightsRecentUnitsAndSettlesOnAConstantRate) {
  EtaEstimator eta(0.25);
  eta.start(0.0, 0);
  eta.record(10.0, 1);  // first unit: 10 s
  EXPECT_DOUBLE_EQ(*eta.seconds_per_unit(), 10.0);
  eta.record(30.0, 2);  // a 20 s unit moves the mean by a quarter of the difference
  EXPECT_DOUBLE_EQ(*eta.seconds_per_unit(), 12.5);
  eta.record(30.0, 2);  // no new unit: nothing changes
  EXPECT_DOUBLE_EQ(*eta.seconds_per_unit(), 12.5);
  // Two units at once: weight 1 - 0.75^2 on their 5 s each.
  eta.record(40.0, 4);
  EXPECT_DOUBLE_EQ(*eta.seconds_per_unit(), (1.0 - 0.5625) * 5.0 + 0.5625 * 12.5);
  double t = 40.0;
  for (std::size_t done = 5; done < 60; ++done) eta.record(t += 8.0, done);
  EXPECT_NEAR(*eta.seconds_per_unit(), 8.0, 1e-6);
}

TEST(Eta, CountsDownDuringAUnitAndStallsWhenItRunsLong) {
  EtaEstimator eta;
  eta.start(0.0, 0);
  eta.record(10.0, 1);
  EXPECT_DOUBLE_EQ(*eta.remaining(10.0, 4), 30.0);
  EXPECT_DOUBLE_EQ(*eta.remaining(14.0, 4), 26.0);
  EXPECT_DOUBLE_EQ(*eta.remaining(25.0, 4), 20.0);  // the unit overran: never grows
  EXPECT_DOUBLE_EQ(*eta.remaining(25.0, 1), 0.0);
}

TEST(Eta, UnitsBeforeTheStartAreNotTimed) {
  EtaEstimator eta;
  eta.start(100.0, 6);  // resumed after 6 units
  eta.record(103.0, 7);
  EXPECT_DOUBLE_EQ(*eta.seconds_per_unit(), 3.0);
  EXPECT_DOUBLE_EQ(*eta.remaining(103.0, 10), 9.0);
}

}  // namespace
}  // namespace mresim::app
