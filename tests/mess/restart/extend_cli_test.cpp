// `mresim extend`: a finished run extended to more fields or load values ends with the same
// steps, bit for bit, as the extended run file run directly (the continued steps start from the
// exact saved state and the solvers are deterministic); refused keys and protocols that would
// change the computed steps leave the run untouched; an interrupted extend leaves the original
// run as it was and is continued by `mresim resume`.

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>

#include "../../support/child_process.hpp"
#include "restart_cli_support.hpp"

namespace {

namespace fs = std::filesystem;
using mresim::mess_protocol::testing::expect_identical_steps;
using mresim::mess_protocol::testing::kQuiet;
using mresim::mess_protocol::testing::last_stderr;
using mresim::mess_protocol::testing::mresim_in;
using mresim::mess_protocol::testing::small_field_run;
using mresim::mess_protocol::testing::staged_checkpoint;
using mresim::testing::Hdf5Reader;
using mresim::testing::read_text;
using mresim::testing::TempDir;

TEST(MessExtendCli, HigherFieldContinuesFromTheFinalStateAsTheDirectRun) {
  const TempDir dir;
  std::ofstream(dir / "run.toml") << small_field_run(0.04, 2, "up");  // 0, 20, 40 mT
  const std::string more = " --set field.max=0.08 --set field.steps=4";
  ASSERT_EQ(mresim_in(dir.path(), std::string("run run.toml --out out") + kQuiet), 0);
  ASSERT_TRUE(fs::exists(dir / "out" / "final_state.h5"));
  ASSERT_EQ(mresim_in(dir.path(), "extend out" + more + kQuiet), 0) << last_stderr(dir.path());
  EXPECT_EQ(last_stderr(dir.path()).find("computed again"), std::string::npos);
  ASSERT_EQ(mresim_in(dir.path(), "run run.toml --out direct" + more + kQuiet), 0);

  expect_identical_steps(dir / "direct", dir / "out");
  const Hdf5Reader r(dir / "out" / "results.h5");
  EXPECT_EQ(r.ints("/steps/index").size(), 5U);
  // Recorded as the run file it now is, and in the history.
  EXPECT_EQ(r.string_attribute("/", "input_toml"),
            Hdf5Reader(dir / "direct" / "results.h5").string_attribute("/", "input_toml"));
  EXPECT_EQ(r.string_attribute("/", "input_overrides"), "field.max=0.08\nfield.steps=4\n");
  EXPECT_EQ(r.string_attribute("/history/0", "kind"), "extend");
  EXPECT_EQ(r.string_attribute("/history/0", "overrides"), "field.max=0.08\nfield.steps=4");
  EXPECT_EQ(r.string_attribute("/history/0", "command_line"),
            "mresim extend out --set field.max=0.08 --set field.steps=4");
  EXPECT_EQ(r.ints("/history/0/added_steps"), (std::vector<std::int64_t>{3, 4}));
  EXPECT_TRUE(r.ints("/history/0/recomputed_steps").empty());
  EXPECT_TRUE(r.ints("/history/0/replaced_steps").empty());
  EXPECT_FALSE(fs::exists(dir / "out" / ".mresim-history.h5"));
  EXPECT_FALSE(fs::exists(dir / "out" / "checkpoint.h5"));

  // A second extend keeps the first one's entry.
  ASSERT_EQ(mresim_in(dir.path(),
                      "extend out --set field.max=0.1 --set field.steps=5" + std::string(kQuiet)),
            0)
      << last_stderr(dir.path());
  const Hdf5Reader twice(dir / "out" / "results.h5");
  EXPECT_EQ(twice.ints("/steps/index").size(), 6U);
  EXPECT_EQ(twice.string_attribute("/history/1", "overrides"), "field.max=0.1\nfield.steps=5");
  EXPECT_EQ(twice.string_attribute("/history/0", "overrides"), "field.max=0.08\nfield.steps=4");
}

TEST(MessExtendCli, LargerLoopReplacesTheOldReturnBranchFromKeptPositions) {
  const TempDir dir;
  // 0 -> 40 -> -40 -> 40 mT in 20 mT steps (11 steps), extended to 80 mT (21 steps): the
  // extended loop shares the first 3 steps, the old return branch is replaced. (max and steps
  // both doubled give the same 20 mT values bit for bit, so the direct run has the same ones.)
  std::ofstream(dir / "run.toml") << small_field_run(0.04, 2, "loop", true);
  const std::string more = " --set field.max=0.08 --set field.steps=4";
  ASSERT_EQ(mresim_in(dir.path(), std::string("run run.toml --out out") + kQuiet), 0);
  ASSERT_EQ(mresim_in(dir.path(), "extend out" + more + kQuiet), 0) << last_stderr(dir.path());
  const std::string err = last_stderr(dir.path());
  EXPECT_NE(err.find("steps 3 to 10 of the computed run are not steps of the extended protocol"),
            std::string::npos)
      << err;
  EXPECT_EQ(err.find("computed again"), std::string::npos) << err;  // positions were kept
  ASSERT_EQ(mresim_in(dir.path(), "run run.toml --out direct" + more + kQuiet), 0);

  expect_identical_steps(dir / "direct", dir / "out");
  const Hdf5Reader r(dir / "out" / "results.h5");
  EXPECT_EQ(r.ints("/history/0/replaced_steps"),
            (std::vector<std::int64_t>{3, 4, 5, 6, 7, 8, 9, 10}));
  EXPECT_EQ(r.ints("/history/0/replaced/index").size(), 8U);  // the old records
  // The steps at +-60 and +-80 mT.
  EXPECT_EQ(r.ints("/history/0/added_steps"),
            (std::vector<std::int64_t>{3, 4, 5, 11, 12, 13, 19, 20}));
  for (int k = 0; k < 21; ++k) {
    EXPECT_TRUE(fs::exists(dir / "out" / "positions" /
                           ("step_0000" + std::to_string(k / 10) + std::to_string(k % 10) + ".h5")))
        << k;
  }
}

TEST(MessExtendCli, MoreStrainValuesAddOnlyTheNewSteps) {
  const TempDir dir;
  const std::string toml = std::string("[run]\ntype = \"mess_strain\"\n") +
                           mresim::mess_protocol::testing::kSmallModel +
                           "\n[field]\nmagnitudes = [0.0, 0.05]\n\n[strain]\nkind = \"shear\"\n"
                           "values = [0.0, 0.01]\n\n[output]\ncheckpoint_every = 0\n";
  std::ofstream(dir / "run.toml") << toml;
  const std::string more = " --set 'strain.values=[0.0, 0.01, 0.02]'";
  ASSERT_EQ(mresim_in(dir.path(), std::string("run run.toml --out out") + kQuiet), 0);
  ASSERT_EQ(mresim_in(dir.path(), "extend out" + more + kQuiet), 0) << last_stderr(dir.path());
  ASSERT_EQ(mresim_in(dir.path(), "run run.toml --out direct" + more + kQuiet), 0);
  expect_identical_steps(dir / "direct", dir / "out");
  const Hdf5Reader r(dir / "out" / "results.h5");
  EXPECT_EQ(r.ints("/history/0/added_steps"), (std::vector<std::int64_t>{4, 5}));
  // The modulus fit now has three strains per field.
  EXPECT_EQ(r.ints("/analysis/fit_points"),
            Hdf5Reader(dir / "direct" / "results.h5").ints("/analysis/fit_points"));
}

TEST(MessExtendCli, RefusedOverridesNameTheKeyAndLeaveTheRunUntouched) {
  const TempDir dir;
  std::ofstream(dir / "run.toml") << small_field_run(0.04, 2, "up");
  ASSERT_EQ(mresim_in(dir.path(), std::string("run run.toml --out out") + kQuiet), 0);
  const std::string before = read_text(dir / "out" / "results.h5");

  const auto refused = [&](const std::string& args, const std::string& message) {
    EXPECT_EQ(mresim_in(dir.path(), "extend out " + args + kQuiet), 2) << args;
    EXPECT_NE(last_stderr(dir.path()).find(message), std::string::npos)
        << args << ": " << last_stderr(dir.path());
  };
  refused("--set particles.saturation_magnetization=1e6",
          "extend --set particles.saturation_magnetization=1e6: "
          "particles.saturation_magnetization is not a key that lengthens the protocol");
  refused("--set model.discretization_order=2", "a run with another system is a new run");
  refused("--set solver.minimiser.force_tolerance=1e-8", "use 'mresim rerun'");
  // Changes the spacing, so the computed 20 mT step is not in the new sequence.
  refused("--set field.max=0.08",
          "the extended protocol has no step with the field (0, 0, 0.02) T and load 0 of "
          "computed step 1");
  refused("--set field.max=0.04", "adds no field or load value to the 3 computed steps");
  refused("--set field.steps=-1", "field.steps");  // validated as the run file is
  refused("", "no --set given");
  EXPECT_EQ(mresim_in(dir.path(), "extend nothing --set field.max=1" + std::string(kQuiet)), 2);
  EXPECT_NE(last_stderr(dir.path()).find("holds no finished mresim run"), std::string::npos);

  EXPECT_EQ(read_text(dir / "out" / "results.h5"), before);
  for (const auto& e : fs::directory_iterator(dir.path())) {
    EXPECT_EQ(e.path().filename().string().find(".partial-"), std::string::npos) << e.path();
  }
}

TEST(MessExtendCli, KilledExtendLeavesTheRunAsItWasAndResumes) {
  const TempDir dir;
  std::ofstream(dir / "run.toml") << small_field_run(0.04, 2, "up");
  const std::string more = " --set field.max=0.32 --set field.steps=16";  // 14 new steps
  ASSERT_EQ(mresim_in(dir.path(), std::string("run run.toml --out out") + kQuiet), 0);
  const std::string before = read_text(dir / "out" / "results.h5");

  const pid_t pid =
      mresim::testing::start_child(MRESIM_CLI_PATH,
                                   {"extend", "out", "--set", "field.max=0.32", "--set",
                                    "field.steps=16", "--no-plot", "-j", "1"},
                                   dir.path(), "/dev/null", ".stderr-bg");
  ASSERT_GT(pid, 0);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  bool killed = false;
  while (std::chrono::steady_clock::now() < deadline) {
    int status = 0;
    if (::waitpid(pid, &status, WNOHANG) == pid) break;  // finished before it could be killed
    if (!staged_checkpoint(dir.path(), "out").empty()) {
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
      ::kill(pid, SIGKILL);
      ::waitpid(pid, &status, 0);
      killed = WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL;
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  ASSERT_TRUE(killed) << "the extend finished before it could be killed";
  EXPECT_EQ(read_text(dir / "out" / "results.h5"), before);  // the run as it was

  ASSERT_EQ(mresim_in(dir.path(), std::string("resume out") + kQuiet), 0)
      << last_stderr(dir.path());
  ASSERT_EQ(mresim_in(dir.path(), "run run.toml --out direct" + more + kQuiet), 0);
  expect_identical_steps(dir / "direct", dir / "out");
  const Hdf5Reader r(dir / "out" / "results.h5");
  EXPECT_EQ(r.string_attribute("/history/0", "kind"), "extend");  // kept across the resume
  EXPECT_EQ(r.string_attribute("/", "input_overrides"), "field.max=0.32\nfield.steps=16\n");
}

}  // namespace
