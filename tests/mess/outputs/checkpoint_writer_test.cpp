// A run's checkpoints written step after step (CheckpointWriter, checkpoint.hpp): each writes
// only the node arrays that changed since the previous one, the directory holds exactly the
// files the index names, a run resumed from them ends as the uninterrupted one, files left by a
// write that did not finish are removed, and checkpoints of the previous format still resume.

#include <gtest/gtest.h>
#include <hdf5.h>

#include <filesystem>
#include <map>
#include <set>
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
using mresim::testing::write_text;
using testing::expect_same_states;
using testing::spec_of;
using testing::three_field_shear;

std::set<std::string> files_in(const fs::path& dir) {
  std::set<std::string> names;
  if (!fs::exists(dir)) return names;
  for (const auto& entry : fs::directory_iterator(dir)) {
    names.insert(entry.path().filename().string());
  }
  return names;
}

std::set<std::string> named_files(const CheckpointWriter& writer) {
  std::set<std::string> names;
  for (const auto& [path, file] : writer.array_files()) names.insert(file);
  return names;
}

// The run of `spec` from start to end in one go, in memory.
ProtocolState uninterrupted_run(const mess_config::MessSpec& spec) {
  ProtocolRunner runner(spec);
  ProtocolState state = runner.initial_state();
  runner.run(state, nullptr);
  return state;
}

TEST(CheckpointWriter, WritesOnlyTheArraysThatChangedAndResumesToTheSameResults) {
  const std::string toml = three_field_shear();
  const mess_config::MessSpec spec = spec_of(toml);
  const ProtocolState expected = uninterrupted_run(spec);
  ASSERT_EQ(expected.records.size(), 9U);

  const TempDir dir;
  const fs::path arrays = dir / kArrayDirectory;
  {
    ProtocolRunner first(spec);
    first.set_scratch_directory(dir.path());
    CheckpointWriter writer(dir.path());
    EXPECT_FALSE(writer.exists());
    ProtocolState state = first.initial_state();
    std::map<std::string, std::string> before;
    for (int k = 0; k < 5; ++k) {
      const StepRecord& record = first.run_next_step(state);
      writer.write(state, first, toml, "test.toml");
      const std::map<std::string, std::string> after = writer.array_files();
      // The step's field has a new state; a zero-strain step also a new reference, a strained
      // step its start (the field's next secant passes through it).
      const std::size_t f = record.step.field_index;
      std::set<std::string> changed = {"/slots/" + std::to_string(f) + "/positions"};
      if (record.step.load_index == 0) changed.insert("/references/" + std::to_string(f));
      if (record.step.load_index > 0) changed.insert("/earlier_load_results/" + std::to_string(f));
      for (const auto& [path, file] : after) {
        const auto old = before.find(path);
        if (changed.count(path) != 0) {
          EXPECT_TRUE(old == before.end() || old->second != file) << path << " after step " << k;
        } else {
          ASSERT_NE(old, before.end()) << path << " after step " << k;
          EXPECT_EQ(old->second, file) << path << " rewritten after step " << k;
        }
      }
      for (const std::string& path : changed) EXPECT_EQ(after.count(path), 1U) << path;
      EXPECT_EQ(files_in(arrays), named_files(writer)) << "after step " << k;
      before = after;
    }
    // Fields 0-2 at zero strain, then fields 0 and 1 at the first strain: three states, three
    // references and the two strained fields' zero-strain results.
    EXPECT_EQ(before.size(), 8U);
  }
  // A write that did not finish (killed) leaves a file the index does not name.
  write_text(arrays / "slots-2-positions-6.h5.tmp", "partial");

  ProtocolRunner second(spec);
  second.set_scratch_directory(dir.path());
  CheckpointWriter writer(dir.path());
  ASSERT_TRUE(writer.exists());
  ProtocolState state = writer.read(second, toml);
  ASSERT_EQ(state.next_step, 5U);
  EXPECT_EQ(files_in(arrays), named_files(writer));  // the partial file is gone
  EXPECT_EQ(writer.array_files().size(), 8U);
  // The first write after the resume keeps the files it read; only the step's arrays are new.
  second.run_next_step(state);
  const std::map<std::string, std::string> read_files = writer.array_files();
  writer.write(state, second, toml, "test.toml");
  std::size_t kept = 0;
  for (const auto& [path, file] : writer.array_files()) {
    const auto old = read_files.find(path);
    if (old != read_files.end() && old->second == file) ++kept;
  }
  EXPECT_EQ(kept, 7U);  // all but field 2's state (its start is new)
  second.run(state, [&](const ProtocolState& s) { writer.write(s, second, toml, "test.toml"); });
  expect_same_states(expected, state);
  EXPECT_EQ(files_in(arrays), named_files(writer));

  writer.remove();
  EXPECT_FALSE(writer.exists());
  EXPECT_FALSE(fs::exists(arrays));
  EXPECT_TRUE(files_in(dir.path()).empty());
}

TEST(CheckpointWriter, ResumesFromACheckpointOfThePreviousFormat) {
  // Format 2 held every array inside the checkpoint file; a run interrupted under it resumes.
  const std::string toml = three_field_shear();
  const mess_config::MessSpec spec = spec_of(toml);
  const ProtocolState expected = uninterrupted_run(spec);

  const TempDir dir;
  const fs::path file = dir / kCheckpointFile;
  {
    ProtocolRunner first(spec);
    ProtocolState partial = first.initial_state();
    for (int i = 0; i < 4; ++i) first.run_next_step(partial);
    write_checkpoint(file, partial, first, toml, "test.toml");
  }
  {
    const hid_t h5 = H5Fopen(file.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    ASSERT_GE(h5, 0);
    const hid_t attribute = H5Aopen(h5, "format_version", H5P_DEFAULT);
    const long long two = 2;
    EXPECT_GE(H5Awrite(attribute, H5T_NATIVE_LLONG, &two), 0);
    H5Aclose(attribute);
    H5Fclose(h5);
  }
  ProtocolRunner second(spec);
  CheckpointWriter writer(dir.path());
  ProtocolState state = writer.read(second, toml);
  ASSERT_EQ(state.next_step, 4U);
  EXPECT_TRUE(writer.array_files().empty());  // every array was inside the file
  second.run(state, [&](const ProtocolState& s) { writer.write(s, second, toml, "test.toml"); });
  expect_same_states(expected, state);
}

}  // namespace
}  // namespace mresim::mess_protocol
