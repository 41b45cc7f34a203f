// `mresim resume`: a 3D run killed with SIGKILL in the middle of its steps and resumed ends with
// the same results as an uninterrupted run (issue requirement), and resuming where nothing was
// interrupted is a clear error.

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <thread>

#include "../../support/child_process.hpp"
#include "../../support/hdf5_read.hpp"
#include "../../support/temp_dir.hpp"
#include "../restart/restart_cli_support.hpp"
#include "../support/small_runs.hpp"

namespace {

namespace fs = std::filesystem;
using mresim::mess_protocol::testing::mresim_in;
using mresim::mess_protocol::testing::staged_checkpoint;
using mresim::testing::Hdf5Reader;
using mresim::testing::TempDir;

// Starts `mresim ARGS...` in `dir` without waiting for it (stdout to /dev/null, stderr to
// `dir`/.stderr-<tag>).
pid_t start_mresim(const fs::path& dir, const std::vector<std::string>& args,
                   const std::string& tag = "bg") {
  return mresim::testing::start_child(MRESIM_CLI_PATH, args, dir, "/dev/null", ".stderr-" + tag);
}

// The runs here use one thread (all but the SIGTERM test's stopped run, which keeps the
// default): ctest runs two tests at once on CI's two cores, and two OpenMP threads per run,
// spinning while they wait, made the ten-kill test below take 139 s there instead of 14 s.
// Results do not depend on the thread count (MessSolvers.IndependentOfThreadCount), so one
// thread tests the same resume.
// Starts `mresim run FILE --out OUT --no-plot -j 1` in `dir` without waiting for it.
pid_t start_run(const fs::path& dir, const std::string& file, const std::string& out) {
  return start_mresim(dir, {"run", file, "--out", out, "--no-plot", "-j", "1"});
}

// The step datasets two runs of the same file must agree on bit for bit.
void expect_identical_resumed_steps(const fs::path& a_dir, const fs::path& b_dir) {
  const Hdf5Reader a(a_dir / "results.h5");
  const Hdf5Reader b(b_dir / "results.h5");
  for (const char* path :
       {"/steps/field", "/steps/energies/total", "/steps/energies/springs",
        "/steps/energies/volume", "/steps/energies/dipole", "/steps/energies/zeeman",
        "/steps/centres", "/steps/magnetization", "/steps/separation", "/steps/solver/max_force"}) {
    EXPECT_EQ(a.doubles(path), b.doubles(path)) << path;
  }
  EXPECT_EQ(a.ints("/steps/solver/iterations"), b.ints("/steps/solver/iterations"));
  // Read back from the checkpoint for the steps before the resume, like the numbers above.
  EXPECT_EQ(a.strings("/steps/solver/finished_by"), b.strings("/steps/solver/finished_by"));
  EXPECT_EQ(a.ints("/steps/solver/correction_passes"), b.ints("/steps/solver/correction_passes"));
}

int exit_status_of(pid_t pid) { return mresim::testing::wait_child(pid); }

TEST(MessResumeCli, KilledRunResumedGivesTheSameResults) {
  const TempDir dir;
  // 51 steps of a few tens of milliseconds each: killed a few steps after its first checkpoint.
  const std::string toml = mresim::mess_protocol::testing::small_hysteresis(0.2, 10);
  { std::ofstream(dir / "run.toml") << toml; }
  ASSERT_EQ(mresim_in(dir.path(), "run run.toml --out full --no-plot -j 1"), 0);

  const pid_t pid = start_run(dir.path(), "run.toml", "killed");
  ASSERT_GT(pid, 0);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  bool killed = false;
  while (std::chrono::steady_clock::now() < deadline) {
    const fs::path checkpoint = staged_checkpoint(dir.path(), "killed");
    int status = 0;
    if (::waitpid(pid, &status, WNOHANG) == pid) break;  // finished before we could kill it
    if (!checkpoint.empty()) {
      // Let it get a step or so past the first checkpoint, then kill it outright.
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
      ::kill(pid, SIGKILL);
      ::waitpid(pid, &status, 0);
      killed = WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL;
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  ASSERT_TRUE(killed) << "the run finished or never checkpointed before it could be killed";
  ASSERT_FALSE(fs::exists(dir / "killed"));  // nothing published by the killed run

  ASSERT_EQ(mresim_in(dir.path(), "resume killed --no-plot -j 1"), 0)
      << mresim::testing::read_text(dir / ".stderr");
  // It continued from the checkpoint rather than starting over.
  EXPECT_NE(mresim::testing::read_text(dir / ".stderr").find("resuming at step"),
            std::string::npos);
  ASSERT_TRUE(fs::exists(dir / "killed" / "results.h5"));
  EXPECT_FALSE(fs::exists(dir / "killed" / "checkpoint.h5"));

  expect_identical_resumed_steps(dir / "full", dir / "killed");
  EXPECT_EQ(Hdf5Reader(dir / "full" / "results.h5").doubles("/steps/field").size(), 51U * 3U);
}

// SIGTERM (Slurm's end-of-job signal) in the middle of a run with checkpoints switched off:
// the run finishes its step, writes a checkpoint anyway, says how to resume and exits with
// 143; the resumed run ends with the same results as an uninterrupted one.
TEST(MessResumeCli, SigtermWritesACheckpointAndTheResumedRunIsIdentical) {
  const TempDir dir;
  {
    std::ofstream(dir / "run.toml") << mresim::mess_protocol::testing::small_hysteresis(0.2, 4, 0);
  }
  ASSERT_EQ(mresim_in(dir.path(), "run run.toml --out full --no-plot -j 1"), 0);

  const pid_t pid = start_mresim(dir.path(), {"run", "run.toml", "--out", "stopped", "--no-plot"});
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (!fs::exists(dir / "stopped.mresim-lock") && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  // At once: the run has just claimed its directory and stops after its first step (a small
  // loop takes well under a second on an idle machine, so any wait would race its end).
  ::kill(pid, SIGTERM);
  ASSERT_EQ(exit_status_of(pid), 143) << mresim::testing::read_text(dir / ".stderr-bg");
  const std::string err = mresim::testing::read_text(dir / ".stderr-bg");
  EXPECT_NE(err.find("mresim: interrupted by SIGTERM after step "), std::string::npos) << err;
  EXPECT_NE(err.find("continue with 'mresim resume stopped'"), std::string::npos) << err;
  EXPECT_FALSE(fs::exists(dir / "stopped"));
  EXPECT_FALSE(fs::exists(dir / "stopped.mresim-lock"));

  ASSERT_EQ(mresim_in(dir.path(), "resume stopped --no-plot -j 1"), 0)
      << mresim::testing::read_text(dir / ".stderr");
  EXPECT_NE(mresim::testing::read_text(dir / ".stderr").find("resuming at step"),
            std::string::npos);
  expect_identical_resumed_steps(dir / "full", dir / "stopped");
}

// While a run is going on, `resume` of its directory is refused without advising a new run
// into the same directory (the lock says who is running).
TEST(MessResumeCli, ResumeWhileTheRunIsGoingOnIsRefused) {
  const TempDir dir;
  { std::ofstream(dir / "run.toml") << mresim::mess_protocol::testing::small_hysteresis(0.2, 4); }
  const pid_t pid = start_run(dir.path(), "run.toml", "busy");
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (!fs::exists(dir / "busy.mresim-lock") && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  EXPECT_EQ(mresim_in(dir.path(), "resume busy --no-plot"), 2);
  const std::string err = mresim::testing::read_text(dir / ".stderr");
  EXPECT_NE(err.find("is in use by mresim run, pid " + std::to_string(pid)), std::string::npos)
      << err;
  EXPECT_NE(err.find("nothing can be resumed while it runs"), std::string::npos) << err;
  EXPECT_EQ(err.find("mresim run'"), std::string::npos) << err;
  ::kill(pid, SIGKILL);  // the run itself was undisturbed until now
  EXPECT_EQ(exit_status_of(pid), 128 + SIGKILL);
}

// The kill test: SIGKILL at 10 random moments (before, during and after checkpoints,
// during resumes), resuming after each; the result is bitwise that of an uninterrupted run.
TEST(MessResumeCli, TenRandomKillsAndResumesGiveTheSameResults) {
  const TempDir dir;
  { std::ofstream(dir / "run.toml") << mresim::mess_protocol::testing::small_hysteresis(0.2, 4); }
  const auto t0 = std::chrono::steady_clock::now();
  ASSERT_EQ(mresim_in(dir.path(), "run run.toml --out full --no-plot -j 1"), 0);
  const fs::path full = dir / "full";
  // The length of one uninterrupted run, from a run of our own if the shared one was made
  // earlier.
  if (std::chrono::steady_clock::now() - t0 < std::chrono::milliseconds(100)) {
    ASSERT_EQ(mresim_in(dir.path(), "run run.toml --out timing --no-plot -j 1"), 0);
  }
  const double full_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();

  std::mt19937 random(20261201);  // fixed seed: reproducible moments, different for each kill
  std::uniform_real_distribution<double> moment(0.05, 0.6);
  int kills = 0;
  bool finished = false;
  for (int attempt = 0; attempt < 60 && !finished; ++attempt) {
    // Continue from a checkpoint if the last kill left one, else start (again) from scratch.
    const pid_t pid = staged_checkpoint(dir.path(), "chain").empty()
                          ? start_run(dir.path(), "run.toml", "chain")
                          : start_mresim(dir.path(), {"resume", "chain", "--no-plot", "-j", "1"});
    if (kills < 10) {
      std::this_thread::sleep_for(
          std::chrono::duration<double, std::milli>(moment(random) * full_ms));
      ::kill(pid, SIGKILL);
    }
    const int status = exit_status_of(pid);
    if (status == 128 + SIGKILL) {
      ++kills;
      continue;
    }
    ASSERT_EQ(status, 0) << mresim::testing::read_text(dir / ".stderr-bg");
    finished = kills >= 10;  // a run that ended before its kill is simply run again
  }
  ASSERT_TRUE(finished);
  EXPECT_EQ(kills, 10);
  expect_identical_resumed_steps(full, dir / "chain");
}

TEST(MessResumeCli, NothingToResumeIsAnInputError) {
  const TempDir dir;
  EXPECT_EQ(mresim_in(dir.path(), "resume nowhere"), 2);
  const std::string err = mresim::testing::read_text(dir / ".stderr");
  EXPECT_NE(err.find("no interrupted run with a checkpoint for 'nowhere'"), std::string::npos)
      << err;
}

}  // namespace
