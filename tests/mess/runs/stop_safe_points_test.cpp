// Which plans stop at safe points of their own (RunPlan::stops_at_own_safe_points): a stop
// signal during their last step must not discard a finished run (docs/cli.md, "Signals";
// tests/cli/run_safety_test.cpp runs the command around it).

#include <gtest/gtest.h>

#include <string>

#include "../support/small_runs.hpp"
#include "mresim/app/run_type.hpp"
#include "mresim/config/table_reader.hpp"
#include "mresim/mess/restart/extend_plan.hpp"

namespace {

namespace mp = mresim::mess_protocol;
using mresim::config::TableReader;

TEST(StopSafePoints, TheThreeDimensionalPlansAndExtendHaveThemThePairRunsNot) {
  const TableReader computed =
      TableReader::parse_string(mp::testing::small_hysteresis(0.02, 2, 1), "run.toml");
  EXPECT_TRUE(mresim::app::make_plan(computed)->stops_at_own_safe_points());
  // extend's plan forwards its run type's answer.
  const TableReader extended =
      TableReader::parse_string(mp::testing::small_hysteresis(0.04, 4, 1), "run.toml");
  mp::HistoryEntry entry;
  entry.kind = "extend";
  EXPECT_TRUE(
      mp::make_extend_plan(computed, extended, "unused", entry)->stops_at_own_safe_points());
  const TableReader pair = TableReader::parse_string(
      "[run]\ntype = \"froehlich_kennelly\"\n[field]\nmax = 0.5\nstep = 0.005\n", "fk.toml");
  EXPECT_FALSE(mresim::app::make_plan(pair)->stops_at_own_safe_points());
}

}  // namespace
