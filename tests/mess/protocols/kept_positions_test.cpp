// The positions a strain run keeps per field, parked in a scratch file (kept_positions.hpp):
// the file gives back every array bit for bit, leaves nothing in its directory, and a strain
// run that parks its fields gives bitwise the results of one that keeps them in memory,
// uninterrupted and resumed from a checkpoint.

#include "mresim/mess/protocols/kept_positions.hpp"

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>

#include "../../support/temp_dir.hpp"
#include "../support/checkpoint_round_trip.hpp"
#include "../support/small_runs.hpp"
#include "mresim/mess/outputs/checkpoint.hpp"
#include "mresim/mess/protocols/protocol_runner.hpp"

namespace mresim::mess_protocol {
namespace {

namespace fs = std::filesystem;
using mresim::testing::TempDir;
using testing::expect_same_states;
using testing::spec_of;
using testing::three_field_shear;

bool directory_is_empty(const fs::path& dir) {
  return fs::directory_iterator(dir) == fs::directory_iterator();
}

TEST(PositionsSpill, GivesEveryArrayBackBitForBitAndLeavesNoFile) {
  const TempDir dir;
  auto spill = std::make_shared<PositionsSpill>(dir.path(), 1000);
  EXPECT_TRUE(directory_is_empty(dir.path()));  // unlinked at once
  const Eigen::Matrix3Xd a = Eigen::Matrix3Xd::Random(3, 1000) * 1e-5;
  const Eigen::Matrix3Xd b = Eigen::Matrix3Xd::Random(3, 1000);
  const std::int64_t ra = spill->write(a);
  const std::int64_t rb = spill->write(b);
  EXPECT_NE(ra, rb);
  EXPECT_EQ(spill->read(ra), a);
  EXPECT_EQ(spill->read(rb), b);
  EXPECT_EQ(spill->records(), 2);
  // A released record is reused: the file does not grow.
  spill->release(ra);
  const Eigen::Matrix3Xd c = -a;
  EXPECT_EQ(spill->write(c), ra);
  EXPECT_EQ(spill->records(), 2);
  EXPECT_EQ(spill->read(ra), c);
  EXPECT_EQ(spill->read(rb), b);
  EXPECT_THROW(spill->write(Eigen::Matrix3Xd::Zero(3, 999)), std::invalid_argument);
  EXPECT_TRUE(directory_is_empty(dir.path()));
}

TEST(PositionsSpill, NamesTheDirectoryItCannotUse) {
  const TempDir dir;
  const fs::path missing = dir / "no_such_directory";
  try {
    PositionsSpill spill(missing, 10);
    ADD_FAILURE() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(missing.string()), std::string::npos) << e.what();
  }
}

TEST(KeptPositions, ParksLoadsAndTakesTheSameArray) {
  const TempDir dir;
  auto spill = std::make_shared<PositionsSpill>(dir.path(), 50);
  const Eigen::Matrix3Xd x = Eigen::Matrix3Xd::Random(3, 50);

  KeptPositions none;
  EXPECT_EQ(none.cols(), 0);
  none.park(spill);  // nothing to park
  EXPECT_FALSE(none.parked());
  EXPECT_EQ(spill->records(), 0);

  KeptPositions kept = x;
  EXPECT_EQ(none.version(), 0U);
  const std::uint64_t version = kept.version();
  EXPECT_NE(version, 0U);
  EXPECT_FALSE(kept.parked());
  kept.park(spill);
  EXPECT_TRUE(kept.parked());
  EXPECT_EQ(kept.version(), version);  // the same value, parked
  EXPECT_EQ(kept.cols(), 50);
  EXPECT_EQ(kept.load(), x);
  EXPECT_EQ(spill->records(), 1);
  {
    // A copy shares the record; the record stays while any copy holds it.
    KeptPositions copy = kept;
    EXPECT_EQ(copy.version(), version);
    EXPECT_EQ(copy.load(), x);
    EXPECT_EQ(copy.take(), x);
    EXPECT_EQ(copy.cols(), 0);
    EXPECT_EQ(copy.version(), 0U);
  }
  EXPECT_EQ(kept.load(), x);
  // Assigning a new array lets the record go: the next park reuses it.
  kept = Eigen::Matrix3Xd(2.0 * x);
  EXPECT_NE(kept.version(), version);  // a new value: a checkpoint writes it again
  EXPECT_FALSE(kept.parked());
  kept.park(spill);
  EXPECT_EQ(spill->records(), 1);
  EXPECT_EQ(kept.take(), 2.0 * x);
  EXPECT_EQ(kept.cols(), 0);
  EXPECT_FALSE(kept.parked());
}

TEST(KeptPositions, AStrainRunThatParksItsFieldsGivesTheSameResults) {
  const std::string toml = three_field_shear();
  const mess_config::MessSpec spec = spec_of(toml);

  ProtocolRunner in_memory(spec);
  ProtocolState held = in_memory.initial_state();
  in_memory.run(held, nullptr);
  ASSERT_EQ(held.records.size(), 9U);
  EXPECT_EQ(held.spill, nullptr);

  const TempDir dir;
  ProtocolRunner parking(spec);
  parking.set_scratch_directory(dir.path());
  ProtocolState parked = parking.initial_state();
  for (std::size_t k = 0; k < 9; ++k) {
    parking.run_next_step(parked);
    // While the next step relaxes, nothing else is held in memory: after each step only the
    // step's own field has its arrays in memory.
    const std::size_t field = parked.records.back().step.field_index;
    for (std::size_t f = 0; f < 3; ++f) {
      if (f == field) continue;
      const bool has_state = parked.slots[f].positions.cols() > 0;
      EXPECT_EQ(parked.slots[f].positions.parked(), has_state) << "after step " << k;
    }
  }
  ASSERT_NE(parked.spill, nullptr);
  // Three arrays per field at most (state, reference, the state at the strain before) and three
  // for the run (a step's strain secant while it relaxes, the two previous fields' misses of
  // theirs: scratch_bytes_per_node in mess_spec.hpp), and the file is not in the directory.
  EXPECT_LE(parked.spill->records(), 9 + 3);
  EXPECT_GT(parked.spill->records(), 9);
  EXPECT_TRUE(directory_is_empty(dir.path()));
  expect_same_states(held, parked);

  // Resumed after step 4 from a checkpoint, parking again: the same results.
  const fs::path checkpoint = dir / "checkpoint.h5";
  {
    ProtocolRunner first(spec);
    first.set_scratch_directory(dir.path());
    ProtocolState partial = first.initial_state();
    for (int i = 0; i < 4; ++i) first.run_next_step(partial);
    write_checkpoint(checkpoint, partial, first, toml, "test.toml");
  }
  ProtocolRunner second(spec);
  second.set_scratch_directory(dir.path());
  ProtocolState resumed = read_checkpoint(checkpoint, second, toml);
  ASSERT_EQ(resumed.next_step, 4U);
  for (const SlotState& slot : resumed.slots) {
    EXPECT_EQ(slot.positions.parked(), slot.positions.cols() > 0);  // parked as read
  }
  second.run(resumed, nullptr);
  expect_same_states(held, resumed);
}

}  // namespace
}  // namespace mresim::mess_protocol
