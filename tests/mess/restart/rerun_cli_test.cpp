// `mresim rerun`: one step relaxed again. With the run's own settings the step comes out bit for
// bit as it was (the state before it is rebuilt exactly, here by recomputing the steps before
// it); with a tighter tolerance only that step changes, and the original is kept in /history.
// Keys other than solver settings and steps the run does not have are refused.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "restart_cli_support.hpp"

namespace {

namespace fs = std::filesystem;
using mresim::mess_protocol::testing::expect_identical_steps;
using mresim::mess_protocol::testing::kQuiet;
using mresim::mess_protocol::testing::last_stderr;
using mresim::mess_protocol::testing::mresim_in;
using mresim::mess_protocol::testing::small_field_run;
using mresim::testing::Hdf5Reader;
using mresim::testing::read_text;
using mresim::testing::TempDir;

// The values of `path` at every step but `skip` (rows of `width` values).
std::vector<double> without_step(const std::vector<double>& values, std::size_t width,
                                 std::size_t skip) {
  std::vector<double> out;
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (i / width != skip) out.push_back(values[i]);
  }
  return out;
}

TEST(MessRerunCli, SameSettingsReproduceTheStepTighterToleranceChangesOnlyIt) {
  const TempDir dir;
  // A loose force tolerance, so that a tighter one has something to do.
  std::ofstream(dir / "run.toml") << small_field_run(0.04, 2, "up") +
                                         "\n[solver.minimiser]\nforce_tolerance = 1e-3\n";
  ASSERT_EQ(mresim_in(dir.path(), std::string("run run.toml --out out") + kQuiet), 0);
  fs::copy(dir / "out", dir / "original", fs::copy_options::recursive);

  // The state before step 1 was not kept (no node positions): step 0 is computed again first.
  ASSERT_EQ(mresim_in(dir.path(), std::string("rerun out --step 1") + kQuiet), 0)
      << last_stderr(dir.path());
  EXPECT_NE(last_stderr(dir.path()).find("steps 0 to 0 are computed again first"),
            std::string::npos);
  expect_identical_steps(dir / "original", dir / "out");

  ASSERT_EQ(mresim_in(dir.path(), "rerun out --step 1 --set solver.minimiser.force_tolerance=1e-9" +
                                      std::string(kQuiet)),
            0)
      << last_stderr(dir.path());
  const Hdf5Reader before(dir / "original" / "results.h5");
  const Hdf5Reader after(dir / "out" / "results.h5");
  for (const char* path : {"/steps/energies/total", "/steps/solver/max_force"}) {
    const std::vector<double> a = before.doubles(path);
    const std::vector<double> b = after.doubles(path);
    EXPECT_EQ(without_step(a, 1, 1), without_step(b, 1, 1)) << path;
    EXPECT_NE(a[1], b[1]) << path;
  }
  EXPECT_EQ(without_step(before.doubles("/steps/centres"), 6, 1),
            without_step(after.doubles("/steps/centres"), 6, 1));
  EXPECT_GT(after.ints("/steps/solver/iterations")[1], before.ints("/steps/solver/iterations")[1]);
  EXPECT_LT(after.doubles("/steps/solver/max_force")[1],
            before.doubles("/steps/solver/max_force")[1]);
  // The run file stays the run's; the history has both reruns, the second with its override and
  // the record it replaced.
  EXPECT_EQ(after.string_attribute("/", "input_toml"), before.string_attribute("/", "input_toml"));
  EXPECT_EQ(after.string_attribute("/history/1", "kind"), "rerun");
  EXPECT_EQ(after.string_attribute("/history/1", "overrides"),
            "solver.minimiser.force_tolerance=1e-9");
  EXPECT_EQ(after.ints("/history/1/replaced_steps"), (std::vector<std::int64_t>{1}));
  EXPECT_EQ(after.ints("/history/1/replaced/solver/iterations"),
            (std::vector<std::int64_t>{before.ints("/steps/solver/iterations")[1]}));
  EXPECT_EQ(after.doubles("/history/1/replaced/energies/total"),
            (std::vector<double>{before.doubles("/steps/energies/total")[1]}));
  EXPECT_TRUE(fs::exists(dir / "out" / "final_state.h5"));
}

// A strain run's later field at a later strain starts from its secant corrected by the two
// previous fields' misses (protocols/load_step_start.hpp). The state before it is rebuilt from
// the kept step files, the misses recomputed from them: the step comes out bit for bit.
TEST(MessRerunCli, AStrainStepThatStartedFromCorrectedSecantsComesOutAsItWas) {
  const TempDir dir;
  std::ofstream(dir / "run.toml") << std::string("[run]\ntype = \"mess_strain\"\n") +
                                         mresim::mess_protocol::testing::kSmallModel +
                                         "\n[field]\nmagnitudes = [0.0, 0.05, 0.1]\n"
                                         "\n[strain]\nkind = \"shear\"\nnormal = \"z\"\n"
                                         "direction = \"x\"\nmax = 0.02\nsteps = 3\n"
                                         "\n[output]\nnode_positions = true\n";
  ASSERT_EQ(mresim_in(dir.path(), std::string("run run.toml --out out") + kQuiet), 0);
  fs::copy(dir / "out", dir / "original", fs::copy_options::recursive);
  // Step 11: the third field at the fourth strain (step n = 3 k + f), started from its secant
  // plus the second field's miss extrapolated in the field.
  const Hdf5Reader results(dir / "original" / "results.h5");
  ASSERT_EQ(results.strings("/steps/solver/start").at(11), "corrected_secant");
  ASSERT_EQ(mresim_in(dir.path(), std::string("rerun out --step 11") + kQuiet), 0)
      << last_stderr(dir.path());
  // Rebuilt from the step files: nothing computed again.
  EXPECT_EQ(last_stderr(dir.path()).find("computed again"), std::string::npos);
  expect_identical_steps(dir / "original", dir / "out");
}

TEST(MessRerunCli, RefusesWhatIsNotASolverSettingOrAStep) {
  const TempDir dir;
  std::ofstream(dir / "run.toml") << small_field_run(0.04, 2, "up");
  ASSERT_EQ(mresim_in(dir.path(), std::string("run run.toml --out out") + kQuiet), 0);
  const std::string before = read_text(dir / "out" / "results.h5");
  EXPECT_EQ(mresim_in(dir.path(), "rerun out --step 1 --set field.max=0.1" + std::string(kQuiet)),
            2);
  EXPECT_NE(
      last_stderr(dir.path()).find("rerun --set field.max=0.1: field.max is not a solver setting"),
      std::string::npos)
      << last_stderr(dir.path());
  EXPECT_EQ(mresim_in(dir.path(), std::string("rerun out --step 3") + kQuiet), 2);
  EXPECT_NE(last_stderr(dir.path()).find("--step 3: the run has 3 steps (0 to 2)"),
            std::string::npos)
      << last_stderr(dir.path());
  EXPECT_EQ(mresim_in(dir.path(), "rerun out --step 0 --set solver.minimiser.force_tolerance=-1" +
                                      std::string(kQuiet)),
            2);
  EXPECT_NE(last_stderr(dir.path()).find("force_tolerance"), std::string::npos);
  EXPECT_EQ(read_text(dir / "out" / "results.h5"), before);
}

}  // namespace
