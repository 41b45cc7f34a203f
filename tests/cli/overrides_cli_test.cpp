// `mresim run/info FILE --set KEY=VALUE` (docs/cli.md): the override changes the run as if it
// were written in the file, results.h5 records the effective run file, the overrides and the
// file as written, a plain run records exactly what it did before, and `mresim resume` of an
// interrupted run with overrides records the same.

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "../mess/support/small_runs.hpp"
#include "../support/child_process.hpp"
#include "../support/hdf5_read.hpp"
#include "../support/temp_dir.hpp"

namespace {

namespace fs = std::filesystem;
using mresim::testing::CommandResult;
using mresim::testing::Hdf5Reader;
using mresim::testing::read_text;
using mresim::testing::TempDir;
using mresim::testing::write_text;

// Runs the real `mresim` with `args` in `dir` and waits for it.
CommandResult run_mresim_in(const fs::path& dir, const std::vector<std::string>& args) {
  return mresim::testing::run_program(MRESIM_CLI_PATH, dir, args, "-set");
}

const fs::path kExample =
    fs::path(MRESIM_SOURCE_DIR) / "examples" / "fig2_2_single_spring_axial.toml";

TEST(CliOverrides, ARunWithSetComputesAndRecordsTheOverriddenFile) {
  const TempDir dir;
  fs::copy_file(kExample, dir / "pair.toml");
  const std::string file = read_text(dir / "pair.toml");
  ASSERT_EQ(run_mresim_in(dir.path(), {"run", "pair.toml", "--out", "plain", "--no-plot"}).status,
            0);
  const CommandResult r =
      run_mresim_in(dir.path(), {"run", "pair.toml", "--out", "set", "--no-plot", "--set",
                                 "field.max=0.5", "--set", "field.step=0.05"});
  ASSERT_EQ(r.status, 0) << r.err;

  // The plain run records the file byte for byte and nothing about overrides.
  const Hdf5Reader plain(dir / "plain" / "results.h5");
  EXPECT_EQ(plain.string_attribute("/", "input_toml"), file);
  EXPECT_FALSE(plain.has_attribute("/", "input_overrides"));
  EXPECT_FALSE(plain.has_attribute("/", "input_file_toml"));

  const Hdf5Reader set(dir / "set" / "results.h5");
  const std::string effective = set.string_attribute("/", "input_toml");
  EXPECT_NE(effective.find("max = 0.5\n"), std::string::npos) << effective;
  EXPECT_NE(effective.find("step = 0.05"), std::string::npos) << effective;
  EXPECT_EQ(effective.find("max = 1.0"), std::string::npos) << effective;
  EXPECT_EQ(set.string_attribute("/", "input_overrides"), "field.max=0.5\nfield.step=0.05\n");
  EXPECT_EQ(set.string_attribute("/", "input_file_toml"), file);
  EXPECT_EQ(set.string_attribute("/", "input_file"), "pair.toml");
  EXPECT_FALSE(fs::exists(dir / "set" / ".mresim-overrides.toml"));

  // The numbers follow the override: 0 -> 1 -> -1 -> 1 T in 0.01 T (501 fields) against
  // 0 -> 0.5 -> -0.5 -> 0.5 T in 0.05 T (51 fields).
  const auto plain_field = plain.doubles("/cases/0/field");
  const auto set_field = set.doubles("/cases/0/field");
  EXPECT_EQ(plain_field.size(), 501U);
  ASSERT_EQ(set_field.size(), 51U);
  EXPECT_DOUBLE_EQ(*std::max_element(plain_field.begin(), plain_field.end()), 1.0);
  EXPECT_DOUBLE_EQ(*std::max_element(set_field.begin(), set_field.end()), 0.5);
  EXPECT_NEAR(set_field[1], 0.05, 1e-15);

  // The recorded effective file, run as a file of its own, gives the same numbers.
  write_text(dir / "effective.toml", effective);
  ASSERT_EQ(
      run_mresim_in(dir.path(), {"run", "effective.toml", "--out", "again", "--no-plot"}).status,
      0);
  const Hdf5Reader again(dir / "again" / "results.h5");
  EXPECT_EQ(again.doubles("/cases/0/field"), set_field);
  EXPECT_EQ(again.doubles("/cases/0/separation"), set.doubles("/cases/0/separation"));
}

TEST(CliOverrides, InfoShowsWhatAnOverrideGives) {
  const TempDir dir;
  fs::copy_file(kExample, dir / "pair.toml");
  const CommandResult r =
      run_mresim_in(dir.path(), {"info", "pair.toml", "--set", "springs.k=0.05"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("overrides  springs.k=0.05"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("0.05 N/m"), std::string::npos) << r.out;
  const CommandResult plain = run_mresim_in(dir.path(), {"info", "pair.toml"});
  EXPECT_EQ(plain.out.find("overrides"), std::string::npos) << plain.out;
}

TEST(CliOverrides, BadOverridesExitWith2AndWriteNothing) {
  const TempDir dir;
  fs::copy_file(kExample, dir / "pair.toml");
  const CommandResult range =
      run_mresim_in(dir.path(), {"run", "pair.toml", "--set", "field.max=-1"});
  EXPECT_EQ(range.status, 2);
  EXPECT_EQ(range.err, "mresim: error: field.max = -1: must be > 0 (T)\n");
  const CommandResult unknown =
      run_mresim_in(dir.path(), {"run", "pair.toml", "--set", "field.maxx=1"});
  EXPECT_EQ(unknown.status, 2);
  EXPECT_EQ(unknown.err,
            "mresim: error: unknown key 'field.maxx' in [field]; allowed keys: angle, max, step\n");
  const CommandResult parent =
      run_mresim_in(dir.path(), {"run", "pair.toml", "--set", "field.max.x=1"});
  EXPECT_EQ(parent.status, 2);
  EXPECT_EQ(parent.err,
            "mresim: error: --set: field.max.x=1: field.max = 1.0 is a float, not a "
            "table\n");
  // Malformed: refused while the command line is parsed, before the file is read.
  const CommandResult form = run_mresim_in(dir.path(), {"run", "absent.toml", "--set", "fieldmax"});
  EXPECT_EQ(form.status, 2);
  EXPECT_EQ(form.err.rfind("mresim: error: --set: fieldmax: expected KEY=VALUE", 0), 0U)
      << form.err;
  // One argument per --set: FILE after it is not swallowed.
  const CommandResult order =
      run_mresim_in(dir.path(), {"info", "--set", "field.max=0.5", "pair.toml"});
  EXPECT_EQ(order.status, 0) << order.err;
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir.path())) names.push_back(e.path().filename());
  EXPECT_EQ(names, std::vector<std::string>{"pair.toml"});
}

// A 3D run with --set stopped by SIGTERM after its first step and resumed: the resumed run
// computes with the overridden file and records what an uninterrupted run records.
TEST(CliOverrides, AResumedRunKeepsTheOverrides) {
  const TempDir dir;
  write_text(dir / "run.toml", mresim::mess_protocol::testing::small_hysteresis(0.2, 4, 0));
  const std::vector<std::string> set = {"--set", "field.max=0.1", "--set", "run.title=small"};
  std::vector<std::string> full = {"run", "run.toml", "--out", "full", "--no-plot", "-j", "2"};
  full.insert(full.end(), set.begin(), set.end());
  ASSERT_EQ(run_mresim_in(dir.path(), full).status, 0);

  std::vector<std::string> stopped = {"run", "run.toml", "--out", "stopped", "--no-plot"};
  stopped.insert(stopped.end(), set.begin(), set.end());
  const pid_t pid =
      mresim::testing::start_child(MRESIM_CLI_PATH, stopped, dir.path(), "/dev/null", ".stderr-bg");
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (!fs::exists(dir / "stopped.mresim-lock") && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  ::kill(pid, SIGTERM);  // at once: a small loop ends well within a second
  ASSERT_EQ(mresim::testing::wait_child(pid), 143) << read_text(dir / ".stderr-bg");

  const CommandResult resumed =
      run_mresim_in(dir.path(), {"resume", "stopped", "--no-plot", "-j", "2"});
  ASSERT_EQ(resumed.status, 0) << resumed.err;
  EXPECT_NE(resumed.err.find("resuming at step"), std::string::npos) << resumed.err;
  EXPECT_EQ(resumed.err.find("warning"), std::string::npos) << resumed.err;
  EXPECT_FALSE(fs::exists(dir / "stopped" / ".mresim-overrides.toml"));

  const Hdf5Reader a(dir / "full" / "results.h5");
  const Hdf5Reader b(dir / "stopped" / "results.h5");
  for (const char* name : {"input_toml", "input_overrides", "input_file_toml", "input_file"}) {
    EXPECT_EQ(a.string_attribute("/", name), b.string_attribute("/", name)) << name;
  }
  EXPECT_EQ(b.string_attribute("/", "input_overrides"), "field.max=0.1\nrun.title=small\n");
  EXPECT_EQ(b.string_attribute("/", "input_file_toml"), read_text(dir / "run.toml"));
  const auto field = b.doubles("/steps/field");
  EXPECT_EQ(field, a.doubles("/steps/field"));
  EXPECT_EQ(b.doubles("/steps/energies/total"), a.doubles("/steps/energies/total"));
  EXPECT_EQ(b.string_attribute("/", "title"), "small");
  // 0 -> 0.1 -> -0.1 -> 0.1 T: |B| reaches the overridden maximum, never more.
  ASSERT_FALSE(field.empty());
  for (const double x : field) EXPECT_LE(std::abs(x), 0.1 + 1e-12);
  EXPECT_NE(
      std::find_if(field.begin(), field.end(), [](double x) { return std::abs(x) > 0.1 - 1e-12; }),
      field.end());
}

}  // namespace
