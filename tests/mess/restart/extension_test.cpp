// The checks `mresim extend` and `mresim rerun` make before anything runs: which --set keys they
// accept, and whether an extended plan keeps the computed steps (extension.hpp).

#include "mresim/mess/restart/extension.hpp"

#include <gtest/gtest.h>

#include <functional>
#include <string>
#include <vector>

#include "../support/small_runs.hpp"
#include "mresim/config/config_error.hpp"
#include "mresim/mess/protocols/step_plan.hpp"
#include "mresim/mess/restart/restart_overrides.hpp"

namespace {

namespace mp = mresim::mess_protocol;
using mresim::config::ConfigError;

std::vector<mp::StepSpec> hysteresis_steps(const std::string& field_table) {
  return mp::plan_steps(mp::testing::spec_of(std::string("[run]\ntype = \"mess_hysteresis\"\n") +
                                             mp::testing::kSmallModel + "\n[field]\n" +
                                             field_table));
}

std::string config_error_message_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

TEST(MessExtension, AHigherUpSequenceSharesEveryComputedStep) {
  const auto computed = hysteresis_steps("max = 0.04\nsteps = 2\nsequence = \"up\"\n");
  const auto extended = hysteresis_steps("max = 0.08\nsteps = 4\nsequence = \"up\"\n");
  const mp::Extension e = mp::plan_extension(computed, extended, "--set field.max=0.08");
  EXPECT_EQ(e.shared, 3U);
  EXPECT_EQ(e.added, (std::vector<std::int64_t>{3, 4}));
  EXPECT_TRUE(e.replaced.empty());
}

TEST(MessExtension, AValuesListMatchesMaxAndStepsToTheLastBits) {
  // 0.1 / 5 and 0.02 written out differ in the last bit at most: still the same steps.
  const auto computed = hysteresis_steps("max = 0.1\nsteps = 5\nsequence = \"up\"\n");
  const auto extended = hysteresis_steps(
      "magnitudes = [0.0, 0.02, 0.04, 0.06, 0.08, 0.1, 0.12]\nsequence = \"up\"\n");
  EXPECT_EQ(mp::plan_extension(computed, extended, "x").shared, 6U);
}

TEST(MessExtension, ALargerLoopReplacesTheOldReturnBranch) {
  const auto computed = hysteresis_steps("max = 0.04\nsteps = 2\n");  // loop: 11 steps
  const auto extended = hysteresis_steps("max = 0.08\nsteps = 4\n");  // 21 steps
  const mp::Extension e = mp::plan_extension(computed, extended, "x");
  EXPECT_EQ(e.shared, 3U);
  EXPECT_EQ(e.replaced.size(), 8U);
  EXPECT_EQ(e.added.size(), 8U);
}

TEST(MessExtension, RefusesPlansThatDropAComputedStepOrAddNone) {
  const auto computed = hysteresis_steps("max = 0.04\nsteps = 2\nsequence = \"up\"\n");
  EXPECT_NE(config_error_message_of([&] {
              mp::plan_extension(computed,
                                 hysteresis_steps("max = 0.08\nsteps = 2\nsequence = \"up\"\n"),
                                 "--set field.max=0.08");
            })
                .find("extend --set field.max=0.08: the extended protocol has no step with the "
                      "field (0, 0, 0.02) T"),
            std::string::npos);
  EXPECT_NE(config_error_message_of([&] {
              mp::plan_extension(computed, computed, "x");
            }).find("adds no field or load value to the 3 computed steps"),
            std::string::npos);
}

TEST(MessRestartOverrides, ExtendTakesSequenceKeysRerunSolverKeys) {
  EXPECT_NO_THROW(mp::check_extend_overrides({"field.max=0.1", "strain.values=[0, 0.1]"}));
  EXPECT_NE(config_error_message_of([] {
              mp::check_extend_overrides({"box.size=[1, 1, 1]"});
            }).find("extend --set box.size=[1, 1, 1]: box.size is not a key that lengthens"),
            std::string::npos);
  EXPECT_NE(config_error_message_of([] { mp::check_extend_overrides({}); }).find("no --set given"),
            std::string::npos);
  EXPECT_NO_THROW(mp::check_rerun_overrides({"solver.method=newton"}));
  EXPECT_NE(config_error_message_of([] {
              mp::check_rerun_overrides({"particles.susceptibility=5"});
            }).find("particles.susceptibility is not a solver setting"),
            std::string::npos);
}

}  // namespace
