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
#include <string>
#include <thread>

#include "../support/hdf5_read.hpp"
#include "../support/temp_dir.hpp"
#include "small_runs.hpp"

namespace {

namespace fs = std::filesystem;
using mresim::testing::Hdf5Reader;
using mresim::testing::TempDir;

// Runs `mresim args` in `dir`, quietly; returns the exit status.
int mresim_status(const fs::path& dir, const std::string& args) {
  const std::string command = "cd '" + dir.string() + "' && '" + MRESIM_CLI_PATH + "' " + args +
                              " >/dev/null 2>'" + (dir / ".stderr").string() + "' </dev/null";
  const int raw = std::system(command.c_str());
  return WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
}

// Starts `mresim run FILE --out OUT --no-plot -j 2` in `dir` without waiting for it.
pid_t start_run(const fs::path& dir, const std::string& file, const std::string& out) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    if (::chdir(dir.c_str()) != 0) ::_exit(127);
    if (std::freopen("/dev/null", "w", stdout) == nullptr) ::_exit(127);
    if (std::freopen("/dev/null", "w", stderr) == nullptr) ::_exit(127);
    ::execl(MRESIM_CLI_PATH, "mresim", "run", file.c_str(), "--out", out.c_str(), "--no-plot", "-j",
            "2", static_cast<char*>(nullptr));
    ::_exit(127);
  }
  return pid;
}

// The checkpoint of the running process's staging directory, once it exists.
fs::path staged_checkpoint(const fs::path& dir, const std::string& out) {
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string name = e.path().filename().string();
    if (name.rfind(out + ".partial-", 0) == 0 && fs::exists(e.path() / "checkpoint.h5")) {
      return e.path() / "checkpoint.h5";
    }
  }
  return {};
}

TEST(MessResumeCli, KilledRunResumedGivesTheSameResults) {
  const TempDir dir;
  // 51 steps of a few tens of milliseconds each: killed a few steps after its first checkpoint.
  const std::string toml = mresim::mess_protocol::testing::small_hysteresis(0.2, 10);
  { std::ofstream(dir / "run.toml") << toml; }
  ASSERT_EQ(mresim_status(dir.path(), "run run.toml --out full --no-plot -j 2"), 0);

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

  ASSERT_EQ(mresim_status(dir.path(), "resume killed --no-plot -j 2"), 0)
      << mresim::testing::read_text(dir / ".stderr");
  // It continued from the checkpoint rather than starting over.
  EXPECT_NE(mresim::testing::read_text(dir / ".stderr").find("resuming at step"),
            std::string::npos);
  ASSERT_TRUE(fs::exists(dir / "killed" / "results.h5"));
  EXPECT_FALSE(fs::exists(dir / "killed" / "checkpoint.h5"));

  const Hdf5Reader a(dir / "full" / "results.h5");
  const Hdf5Reader b(dir / "killed" / "results.h5");
  for (const char* path :
       {"/steps/field", "/steps/energies/total", "/steps/energies/springs",
        "/steps/energies/volume", "/steps/energies/dipole", "/steps/energies/zeeman",
        "/steps/centres", "/steps/magnetization", "/steps/separation", "/steps/solver/max_force"}) {
    EXPECT_EQ(a.doubles(path), b.doubles(path)) << path;
  }
  EXPECT_EQ(a.ints("/steps/solver/iterations"), b.ints("/steps/solver/iterations"));
  EXPECT_EQ(a.doubles("/steps/field").size(), 51U * 3U);
}

TEST(MessResumeCli, NothingToResumeIsAnInputError) {
  const TempDir dir;
  EXPECT_EQ(mresim_status(dir.path(), "resume nowhere"), 2);
  const std::string err = mresim::testing::read_text(dir / ".stderr");
  EXPECT_NE(err.find("no interrupted run with a checkpoint for 'nowhere'"), std::string::npos)
      << err;
}

}  // namespace
