// The legs of the XDMF views (xdmf_outputs.hpp): stretches of steps along which the time value
// (field, or load at one field) strictly rises or falls, so that no file repeats a time.

#include <gtest/gtest.h>

#include <vector>

#include "mresim/mess/outputs/xdmf_outputs.hpp"

namespace mresim::mess_protocol {
namespace {

using Legs = std::vector<std::vector<std::size_t>>;

std::vector<StepRecord> steps_of(const std::vector<std::size_t>& field_index,
                                 const std::vector<double>& load) {
  std::vector<StepRecord> records(field_index.size());
  for (std::size_t i = 0; i < records.size(); ++i) {
    records[i].step.index = i;
    records[i].step.field_index = field_index[i];
    records[i].step.load_value = load[i];
  }
  return records;
}

TEST(XdmfLegs, AHysteresisLoopHasALegPerSweep) {
  // 0 -> 0.1 -> -0.1 -> 0.1 in 0.05 T steps.
  const std::vector<double> b = {0, 0.05, 0.1, 0.05, 0, -0.05, -0.1, -0.05, 0, 0.05, 0.1};
  const auto records =
      steps_of(std::vector<std::size_t>(b.size(), 0), std::vector<double>(b.size()));
  EXPECT_EQ(xdmf_legs(records, b, false), (Legs{{0, 1, 2}, {3, 4, 5, 6}, {7, 8, 9, 10}}));
}

TEST(XdmfLegs, ARepeatedFieldStartsANewLeg) {
  const std::vector<double> b = {0, 0.1, 0.1, 0.2};
  const auto records = steps_of({0, 1, 2, 3}, std::vector<double>(4));
  EXPECT_EQ(xdmf_legs(records, b, false), (Legs{{0, 1}, {2, 3}}));
}

TEST(XdmfLegs, AStrainRunHasALegPerFieldInLoadOrder) {
  // Load-major order: step = load_index x 2 + field_index.
  const auto records = steps_of({0, 1, 0, 1, 0, 1}, {0, 0, 0.01, 0.01, 0.02, 0.02});
  EXPECT_EQ(xdmf_legs(records, {0, 0.1, 0, 0.1, 0, 0.1}, true), (Legs{{0, 2, 4}, {1, 3, 5}}));
}

}  // namespace
}  // namespace mresim::mess_protocol
