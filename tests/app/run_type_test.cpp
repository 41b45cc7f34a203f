#include "mresim/app/run_type.hpp"

#include <gtest/gtest.h>

#include "../support/toml_text.hpp"
#include "mresim/app/threads.hpp"

namespace mresim::app {
namespace {

// The test-only run type "test_dummy" is registered by tests/support/dummy_run_type.cpp.

using mresim::testing::parse;

std::string config_error_of(const std::string& text) {
  try {
    (void)make_plan(parse(text));
  } catch (const config::ConfigError& e) {
    return e.what();
  }
  return "no error";
}

TEST(RunTypes, TheTestRunTypeIsRegisteredAndTheListIsSorted) {
  const RunType* dummy = find_run_type("test_dummy");
  ASSERT_NE(dummy, nullptr);
  EXPECT_EQ(dummy->summary, "Test-only run type");
  EXPECT_EQ(find_run_type("no_such_type"), nullptr);
  const auto& types = run_types();
  EXPECT_TRUE(std::is_sorted(types.begin(), types.end(),
                             [](const RunType& a, const RunType& b) { return a.name < b.name; }));
}

TEST(RunTypes, MakePlanBuildsTheChosenTypeAndDescribesIt) {
  std::string name;
  const auto plan =
      make_plan(parse("[run]\ntype = \"test_dummy\"\n[dummy]\nsteps = 3\nscale = 2\n"), &name);
  EXPECT_EQ(name, "test_dummy");
  InfoReport report;
  plan->describe(report);
  EXPECT_DOUBLE_EQ(report.to_json()["dummy"]["total_length"]["value"].get<double>(), 6.0);
}

TEST(RunTypes, ReadsTheCommonRunTable) {
  const auto root = parse("[run]\ntype = \"test_dummy\"\ntitle = \"Fig 2.2\"\nthreads = 3\n");
  const RunSettings settings = read_run_settings(root);
  EXPECT_EQ(settings.type, "test_dummy");
  EXPECT_EQ(settings.title, "Fig 2.2");
  EXPECT_EQ(settings.threads, 3);
  EXPECT_EQ(read_run_settings(parse("[run]\ntype = \"test_dummy\"\n")).threads, 0);
}

TEST(RunTypes, ReportsProblemsInTheRunTable) {
  EXPECT_EQ(config_error_of("[dummy]\nsteps = 1\n"), "missing table [run]");
  const std::string bad_type = config_error_of("[run]\ntype = \"tset_dummy\"\n");
  EXPECT_EQ(bad_type.rfind("run.type = \"tset_dummy\": must be one of ", 0), 0U) << bad_type;
  EXPECT_NE(bad_type.find("test_dummy"), std::string::npos);
  EXPECT_EQ(config_error_of("[run]\ntype = \"test_dummy\"\nthreads = -1\n[dummy]\nsteps = 1\n"),
            "run.threads = -1: " + threads_allowed());
  // Far more threads than cores only slows a run down (and crashed the OpenMP runtime).
  EXPECT_EQ(
      config_error_of("[run]\ntype = \"test_dummy\"\nthreads = 1000000\n[dummy]\nsteps = 1\n"),
      "run.threads = 1000000: " + threads_allowed());
  EXPECT_EQ(read_run_settings(parse("[run]\ntype = \"test_dummy\"\nthreads = " +
                                    std::to_string(max_threads()) + "\n"))
                .threads,
            max_threads());
}

TEST(RunTypes, RejectsUnknownKeysAfterTheRunTypeHasReadItsTables) {
  EXPECT_EQ(config_error_of("[run]\ntype = \"test_dummy\"\n[dummy]\nsteps = 1\nscael = 2\n"),
            "unknown key 'dummy.scael' in [dummy]; allowed keys: fail_at, nan_at, "
            "own_safe_points, scale, signal_after_last_step, step_seconds, steps");
  EXPECT_EQ(config_error_of("[run]\ntype = \"test_dummy\"\ntitel = \"x\"\n[dummy]\nsteps = 1\n"),
            "unknown key 'run.titel' in [run]; allowed keys: threads, title, type");
  EXPECT_EQ(config_error_of("[run]\ntype = \"test_dummy\"\n[dummy]\nsteps = 1\n[extra]\n"),
            "unknown table [extra]; allowed: dummy, run");
}

TEST(RunTypes, PassesRunTypeErrorsThrough) {
  EXPECT_EQ(config_error_of("[run]\ntype = \"test_dummy\"\n[dummy]\nsteps = 0\n"),
            "dummy.steps = 0: must be >= 1");
}

TEST(Threads, ConfiguresOpenMP) {
  EXPECT_EQ(configure_threads(2), 2);
  const int all = configure_threads(0);
  EXPECT_GE(all, 1);
  EXPECT_EQ(configure_threads(1), 1);
  EXPECT_EQ(configure_threads(0), all);
}

}  // namespace
}  // namespace mresim::app
