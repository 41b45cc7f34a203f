// What `mresim run` guarantees about its output directory while other things happen: a second
// run at the same time, a stop signal, results that are not valid numbers. Runs the test-bed
// command (the real CLI plus the test-only run type test_dummy, whose `step_seconds` makes it
// slow enough to interfere with).

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "../support/child_process.hpp"
#include "../support/hdf5_read.hpp"
#include "../support/temp_dir.hpp"

namespace {

namespace fs = std::filesystem;
using mresim::testing::Hdf5Reader;
using mresim::testing::listing;
using mresim::testing::read_text;
using mresim::testing::TempDir;
using mresim::testing::write_text;

constexpr const char* kSlowRun =
    "[run]\ntype = \"test_dummy\"\n[dummy]\nsteps = 20\nstep_seconds = 0.1\n";

// `mresim_testbed args...` in `dir` in the background, stdout and stderr to <tag>.out/.err.
pid_t start(const fs::path& dir, const std::vector<std::string>& args, const std::string& tag) {
  return mresim::testing::start_child(MRESIM_TESTBED_PATH, args, dir, tag + ".out", tag + ".err");
}

int wait_for(pid_t pid) { return mresim::testing::wait_child(pid); }

// Waits until `path` exists (the run has claimed its directory); false after 30 s.
bool appears(const fs::path& path) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (std::chrono::steady_clock::now() < deadline) {
    if (fs::exists(path)) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return false;
}

// Issue: two runs into one --out both printed "results written"; the later replaced the other.
TEST(RunSafety, ASecondRunIntoARunningDirectoryIsRefusedNamingTheFirst) {
  const TempDir dir;
  write_text(dir / "slow.toml", kSlowRun);
  write_text(dir / "fast.toml", "[run]\ntype = \"test_dummy\"\n[dummy]\nsteps = 1\n");
  const pid_t first = start(dir.path(), {"run", "slow.toml", "--out", "out", "--no-plot"}, "first");
  ASSERT_TRUE(appears(dir / "out.mresim-lock"));
  const pid_t second =
      start(dir.path(), {"run", "fast.toml", "--out", "out", "--no-plot"}, "second");
  EXPECT_EQ(wait_for(second), 2);
  const std::string err = read_text(dir / "second.err");
  EXPECT_NE(err.find("mresim: error: output directory 'out' is in use by mresim run, pid " +
                     std::to_string(first) + " on host"),
            std::string::npos)
      << err;
  EXPECT_EQ(read_text(dir / "second.out"), "");
  EXPECT_EQ(wait_for(first), 0) << read_text(dir / "first.err");
  EXPECT_EQ(Hdf5Reader(dir / "out" / "results.h5").doubles("/dummy/values").size(), 20U);
  EXPECT_FALSE(fs::exists(dir / "out.mresim-lock"));
}

// SIGINT / SIGTERM: a run type without checkpoints stops, publishes nothing, removes what it
// created (the parent directories of --out included) and exits with 128 + the signal.
TEST(RunSafety, AStopSignalEndsARunWithoutCheckpointsLeavingNothing) {
  for (const int signal : {SIGINT, SIGTERM}) {
    const TempDir dir;
    write_text(dir / "slow.toml", kSlowRun);
    const pid_t pid =
        start(dir.path(), {"run", "slow.toml", "--out", "new/parent/out", "--no-plot"}, "run");
    ASSERT_TRUE(appears(dir / "new" / "parent" / "out.mresim-lock"));
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
    ::kill(pid, signal);
    EXPECT_EQ(wait_for(pid), 128 + signal);
    const std::string err = read_text(dir / "run.err");
    EXPECT_NE(err.find(std::string("mresim: interrupted by ") +
                       (signal == SIGINT ? "SIGINT" : "SIGTERM") +
                       " before the results were published; this run type writes no "
                       "checkpoints, nothing was written to 'new/parent/out'"),
              std::string::npos)
        << err;
    EXPECT_EQ(listing(dir.path()), (std::vector<std::string>{"run.err", "run.out", "slow.toml"}));
  }
}

// A stop signal after the last step (here raised by the plan itself while it writes its
// results): a plan that stops at safe points of its own (the 3D run types) has finished its
// computation, so the results are published and the command says so; a plan without such
// points publishes nothing, as above. Both exit with 128 + the signal.
TEST(RunSafety, AStopSignalAfterTheLastStepKeepsTheResultsOfPlansWithOwnSafePoints) {
  for (const bool own : {true, false}) {
    const TempDir dir;
    write_text(dir / "late.toml", std::string("[run]\ntype = \"test_dummy\"\n[dummy]\nsteps = 5\n"
                                              "signal_after_last_step = true\nown_safe_points = ") +
                                      (own ? "true" : "false") + "\n");
    const pid_t pid = start(dir.path(), {"run", "late.toml", "--out", "out", "--no-plot"}, "run");
    const std::string err_file = (dir / "run.err").string();
    EXPECT_EQ(wait_for(pid), 128 + SIGINT) << read_text(err_file);
    if (own) {
      EXPECT_EQ(Hdf5Reader(dir / "out" / "results.h5").doubles("/dummy/values").size(), 5U);
      EXPECT_NE(read_text(err_file).find(
                    "mresim: SIGINT came after the last step; the results are complete in 'out'\n"),
                std::string::npos)
          << read_text(err_file);
    } else {
      EXPECT_FALSE(fs::exists(dir / "out"));
    }
  }
}

// Non-finite results are published with the bad entries marked, and the run fails (status 4).
TEST(RunSafety, NonFiniteResultsAreKeptMarkedAndTheRunExitsWith4) {
  const TempDir dir;
  write_text(dir / "nan.toml", "[run]\ntype = \"test_dummy\"\n[dummy]\nsteps = 6\nnan_at = 2\n");
  const pid_t pid = start(dir.path(), {"run", "nan.toml", "--out", "out", "--no-plot"}, "run");
  EXPECT_EQ(wait_for(pid), 4);
  const std::string err = read_text(dir / "run.err");
  EXPECT_NE(err.find("mresim: error: non-finite results: value at step 2 (written as NaN); the "
                     "results in 'out' are kept with these entries marked invalid"),
            std::string::npos)
      << err;
  const Hdf5Reader h5(dir / "out" / "results.h5");
  EXPECT_EQ(h5.string_attribute("/", "invalid_results"),
            "non-finite results: value at step 2 (written as NaN)");
  const std::vector<double> values = h5.doubles("/dummy/values");
  ASSERT_EQ(values.size(), 6U);
  EXPECT_TRUE(std::isnan(values[2]));
  EXPECT_EQ(values[3], 3.0);
}

TEST(RunSafety, AValidRunRecordsThatNothingIsInvalid) {
  const TempDir dir;
  write_text(dir / "ok.toml", "[run]\ntype = \"test_dummy\"\n[dummy]\nsteps = 2\n");
  const pid_t pid = start(dir.path(), {"run", "ok.toml", "--out", "out", "--no-plot"}, "run");
  EXPECT_EQ(wait_for(pid), 0);
  EXPECT_EQ(Hdf5Reader(dir / "out" / "results.h5").string_attribute("/", "invalid_results"), "");
}

}  // namespace
