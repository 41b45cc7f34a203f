// What `mresim run` and `mresim resume` print while they work, with stderr not a terminal (as in
// a batch job): a line per step (3D runs) or per 10 % (other run types), each as it happens;
// --quiet and --log FILE; and the log of a run stopped by SIGTERM.

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "../mess/support/small_runs.hpp"
#include "../support/child_process.hpp"
#include "../support/temp_dir.hpp"

namespace {

namespace fs = std::filesystem;
using mresim::testing::CommandResult;
using mresim::testing::read_text;
using mresim::testing::TempDir;
using mresim::testing::write_text;

// `mresim_testbed args...` in `dir`, stdout and stderr captured in files (not a terminal).
CommandResult run_testbed(const fs::path& dir, const std::vector<std::string>& args) {
  return mresim::testing::run_program(MRESIM_TESTBED_PATH, dir, args);
}

const char* const kFourStepDummyRun = "[run]\ntype = \"test_dummy\"\n[dummy]\nsteps = 4\n";

TEST(ProgressCli, WithoutATerminalEveryTenPercentIsALine) {
  const TempDir dir;
  write_text(dir / "demo.toml", kFourStepDummyRun);
  const CommandResult r = run_testbed(dir.path(), {"run", "demo.toml", "--no-plot"});
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* line : {"test_dummy: 25% (1/4), elapsed ", "test_dummy: 50% (2/4), elapsed ",
                           "test_dummy: 75% (3/4), elapsed ", "test_dummy: done 4/4 in "}) {
    EXPECT_NE(r.err.find(line), std::string::npos) << line << "\n" << r.err;
  }
  EXPECT_EQ(r.err.find('\r'), std::string::npos) << "no live line without a terminal";
}

TEST(ProgressCli, QuietPrintsNothingButTheLogHasTheLines) {
  const TempDir dir;
  write_text(dir / "demo.toml", kFourStepDummyRun);
  const CommandResult quiet = run_testbed(dir.path(), {"run", "demo.toml", "--no-plot", "--quiet"});
  ASSERT_EQ(quiet.status, 0) << quiet.err;
  EXPECT_EQ(quiet.out, "");
  EXPECT_EQ(quiet.err, "");
  EXPECT_TRUE(fs::exists(dir / "demo" / "results.h5"));

  const CommandResult logged =
      run_testbed(dir.path(), {"run", "demo.toml", "--no-plot", "-q", "--log", "run.log"});
  ASSERT_EQ(logged.status, 0) << logged.err;
  EXPECT_EQ(logged.err, "");
  const std::string log = read_text(dir / "run.log");
  EXPECT_NE(log.find("test_dummy: 50% (2/4)"), std::string::npos) << log;
  EXPECT_NE(log.find("test_dummy: done 4/4 in "), std::string::npos) << log;

  // Without --quiet the log holds what stderr shows (no terminal: the same lines).
  const CommandResult both =
      run_testbed(dir.path(), {"run", "demo.toml", "--no-plot", "--log", "run.log"});
  ASSERT_EQ(both.status, 0) << both.err;
  EXPECT_EQ(read_text(dir / "run.log"), both.err);
}

TEST(ProgressCli, ErrorsReachTheLogAndQuietKeepsThem) {
  const TempDir dir;
  write_text(dir / "bad.toml", "[run]\ntype = \"test_dummy\"\n[dummy]\nsteps = 0\n");
  const CommandResult r = run_testbed(dir.path(), {"run", "bad.toml", "-q", "--log", "bad.log"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("mresim: error: "), std::string::npos) << r.err;
  EXPECT_EQ(read_text(dir / "bad.log"), r.err);
}

TEST(ProgressCli, LogInsideTheOutputDirectoryOrUnwritableIsRefused) {
  const TempDir dir;
  write_text(dir / "demo.toml", kFourStepDummyRun);
  const CommandResult inside =
      run_testbed(dir.path(), {"run", "demo.toml", "--out", "res", "--log", "res/run.log"});
  EXPECT_EQ(inside.status, 2);
  EXPECT_NE(inside.err.find("mresim: error: --log 'res/run.log': lies inside the output "
                            "directory 'res'"),
            std::string::npos)
      << inside.err;
  const CommandResult same =
      run_testbed(dir.path(), {"run", "demo.toml", "--log", "./demo/../demo"});
  EXPECT_EQ(same.status, 2) << same.err;
  const CommandResult missing_dir =
      run_testbed(dir.path(), {"run", "demo.toml", "--log", "no/such/dir/run.log"});
  EXPECT_EQ(missing_dir.status, 2);
  EXPECT_NE(missing_dir.err.find("--log 'no/such/dir/run.log': cannot write it: No such file"),
            std::string::npos)
      << missing_dir.err;
  const CommandResult empty = run_testbed(dir.path(), {"run", "demo.toml", "--log", ""});
  EXPECT_EQ(empty.status, 2);
  EXPECT_NE(empty.err.find("--log '': must name a file"), std::string::npos) << empty.err;
  // Nothing was run or written.
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir.path())) names.push_back(e.path().filename());
  EXPECT_EQ(names, std::vector<std::string>{"demo.toml"});
}

// A 3D run with stderr to a file: the set-up line, then a line per step as it ends; SIGTERM
// after a second leaves everything up to then in the file and in the --log.
TEST(ProgressCli, ThreeDStepLinesSurviveSigterm) {
  const TempDir dir;
  write_text(dir / "run.toml", mresim::mess_protocol::testing::small_hysteresis(0.2, 100, 0));
  const pid_t pid = mresim::testing::start_child(
      MRESIM_CLI_PATH, {"run", "run.toml", "--no-plot", "-j", "1", "--log", "run.log"}, dir.path(),
      ".stdout", ".stderr");
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (read_text(dir / ".stderr").find("step 1/501") == std::string::npos &&
         std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  std::this_thread::sleep_for(std::chrono::seconds(1));
  ::kill(pid, SIGTERM);
  ASSERT_EQ(mresim::testing::wait_child(pid), 143) << read_text(dir / ".stderr");

  const std::string err = read_text(dir / ".stderr");
  EXPECT_NE(err.find("mresim: lattice 10 x 10 x 18 nodes (1800 nodes, 2 particles), 501 steps, "
                     "solver minimiser, memory estimate "),
            std::string::npos)
      << err;
  EXPECT_NE(err.find("mess_hysteresis: step 1/501 (B 0 T): "), std::string::npos) << err;
  EXPECT_NE(err.find("mess_hysteresis: step 2/501 (B 0.002 T): "), std::string::npos) << err;
  EXPECT_NE(err.find(" iterations, max force "), std::string::npos) << err;
  EXPECT_NE(err.find(", converged yes, "), std::string::npos) << err;
  EXPECT_NE(err.find("mresim: interrupted by SIGTERM after step "), std::string::npos) << err;
  // The log holds the same lines (not the signal handler's own notice, written to stderr).
  const std::string log = read_text(dir / "run.log");
  EXPECT_NE(log.find("mess_hysteresis: step 2/501 (B 0.002 T): "), std::string::npos) << log;
  EXPECT_NE(log.find("mresim: interrupted by SIGTERM after step "), std::string::npos) << log;
  EXPECT_EQ(log.find("stopping at the next safe point"), std::string::npos) << log;
}

}  // namespace
