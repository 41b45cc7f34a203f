// What `mresim rerun` and `mresim extend` read of a finished 3D run (saved_run.hpp): the step
// files of positions/ are only found, not read, until a state needs them; the final state's
// arrays stay parked where the reading runner parks; and the states rebuilt from either are
// bitwise those the run had.

#include "mresim/mess/restart/saved_run.hpp"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

#include "restart_cli_support.hpp"

namespace {

namespace fs = std::filesystem;
namespace mp = mresim::mess_protocol;
using mp::testing::kQuiet;
using mp::testing::kSmallModel;
using mp::testing::mresim_in;
using mp::testing::small_field_run;
using mp::testing::spec_of;
using mresim::testing::Hdf5Reader;
using mresim::testing::TempDir;

// The run file a finished run was made from (results.h5's /@input_toml).
std::string input_toml_of(const fs::path& run) {
  return Hdf5Reader(run / "results.h5").string_attribute("/", "input_toml");
}

TEST(SavedRun, StepFilesAreReadOnlyWhenAStateNeedsThem) {
  const TempDir dir;
  std::ofstream(dir / "run.toml") << small_field_run(0.04, 2, "up", /*node_positions=*/true);
  ASSERT_EQ(mresim_in(dir.path(), std::string("run run.toml --out out") + kQuiet), 0);
  const std::string toml = input_toml_of(dir / "out");
  const mp::ProtocolRunner runner(spec_of(toml));
  const std::size_t steps = runner.steps().size();
  ASSERT_EQ(steps, 3U);

  const mp::SavedRun saved = mp::read_saved_run(dir / "out", runner, toml);
  // Step 0 only in its step file; the last two also in the final state, held: its slot and
  // the result before it, which the field secant of a next step needs.
  ASSERT_TRUE(runner.keeps_earlier_field_result());
  ASSERT_EQ(saved.positions.size(), steps);
  EXPECT_TRUE(saved.positions.at(0).in_step_file());
  EXPECT_FALSE(saved.positions.at(1).in_step_file());
  EXPECT_FALSE(saved.positions.at(steps - 1).in_step_file());

  // What load() reads is the step file's /positions, bit for bit.
  // What load() reads is the step file's /positions, bit for bit, and the final state's copy of
  // step 1 is the same array.
  const auto step_file = [&](int k) {
    return Hdf5Reader(dir / "out" / "positions" / fmt::format("step_{:06d}.h5", k))
        .doubles("/positions");
  };
  const std::vector<double> stored = step_file(0);
  const Eigen::Matrix3Xd loaded = saved.positions.at(0).load();
  ASSERT_EQ(static_cast<std::size_t>(loaded.size()), stored.size());
  EXPECT_TRUE(std::equal(stored.begin(), stored.end(), loaded.data()));
  const std::vector<double> stored_1 = step_file(1);
  const Eigen::Matrix3Xd held_1 = saved.positions.at(1).load();
  EXPECT_TRUE(std::equal(stored_1.begin(), stored_1.end(), held_1.data()));

  // The state after step 1 starts from step 1's array and magnetizations, with step 0's array
  // as the earlier field's result.
  const std::optional<mp::ProtocolState> state = mp::state_after(saved, runner, 2);
  ASSERT_TRUE(state.has_value());
  EXPECT_EQ(state->next_step, 2U);
  EXPECT_TRUE(state->slots[0].positions.load() == held_1);
  EXPECT_TRUE(state->slots[0].magnetization == saved.records[1].magnetization);
  EXPECT_TRUE(state->earlier_field_result.load() == loaded);
  // After step 0 there is no earlier result yet.
  const std::optional<mp::ProtocolState> first = mp::state_after(saved, runner, 1);
  ASSERT_TRUE(first.has_value());
  EXPECT_EQ(first->earlier_field_result.cols(), 0);
}

TEST(SavedRun, StatesOfManyFieldsAreRebuiltParkedWhereTheRunnerParks) {
  const TempDir dir;
  std::ofstream(dir / "run.toml")
      << std::string("[run]\ntype = \"mess_strain\"\n") + kSmallModel +
             "\n[field]\nmagnitudes = [0.0, 0.05]\n\n[strain]\nkind = \"shear\"\n"
             "values = [0.0, 0.01]\n\n[output]\ncheckpoint_every = 0\n";
  ASSERT_EQ(mresim_in(dir.path(), std::string("run run.toml --out out") + kQuiet), 0);
  const std::string toml = input_toml_of(dir / "out");

  // Read once in memory, once by a runner with a scratch directory.
  const mp::ProtocolRunner plain(spec_of(toml));
  const mp::SavedRun in_memory = mp::read_saved_run(dir / "out", plain, toml);
  mp::ProtocolRunner parking(spec_of(toml));
  fs::create_directories(dir / "scratch");
  parking.set_scratch_directory(dir / "scratch");
  const mp::SavedRun parked = mp::read_saved_run(dir / "out", parking, toml);

  const std::size_t steps = plain.steps().size();
  const std::optional<mp::ProtocolState> a = mp::state_after(in_memory, plain, steps);
  const std::optional<mp::ProtocolState> b = mp::state_after(parked, parking, steps);
  ASSERT_TRUE(a.has_value() && b.has_value());
  ASSERT_EQ(a->slots.size(), 2U);  // one per field
  ASSERT_EQ(b->slots.size(), 2U);
  for (std::size_t s = 0; s < 2; ++s) {
    EXPECT_FALSE(a->slots[s].positions.parked()) << s;
    EXPECT_TRUE(b->slots[s].positions.parked()) << s;
    EXPECT_GT(b->slots[s].positions.cols(), 0) << s;
    EXPECT_TRUE(a->slots[s].positions.load() == b->slots[s].positions.load()) << s;
    EXPECT_TRUE(b->references[s].parked()) << s;
    EXPECT_TRUE(a->references[s].load() == b->references[s].load()) << s;
  }
  // The scratch file is unlinked at once: nothing is left in its directory.
  EXPECT_TRUE(fs::is_empty(dir / "scratch"));
}

}  // namespace
