#pragma once

// Checkpoints of 3D runs: the whole ProtocolState (the latest state at every field, the
// zero-load references, the records of the steps done) plus the run file it belongs to, so that
// `mresim resume` continues a killed run and ends with the same results as an uninterrupted one.
//
// A checkpoint is one file (<file>, the index) or the index plus array files. The index holds
// the counters, the run file, the records, the particles' magnetizations, and for every node
// array (the fields' states and references, the field secant's earlier result, the
// preconditioner's anchor) either the array itself or the name of the file beside it that holds
// it (directory kArrayDirectory next to the index). write_checkpoint writes one
// self-contained file (the final state of a run, kept with its results); a CheckpointWriter
// writes a run's checkpoints step after step, each node array once: an array unchanged since
// the previous checkpoint keeps its file. For the full-size Fig. 4.25 helix (12 fields, 24 MB
// per array) that is one or two arrays per step instead of all 25 (docs/outputs-3d.md, "Checkpoints
// and resume").
//
// Every file is written to "<name>.tmp" and renamed over <name>, the index last: a run killed
// while writing leaves the previous checkpoint intact, and its arrays.

#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <string_view>

#include "mresim/mess/protocols/protocol_runner.hpp"

namespace mresim::mess_protocol {

inline constexpr const char* kCheckpointFile = "checkpoint.h5";
// Beside the index: the array files of a CheckpointWriter's checkpoints.
inline constexpr const char* kArrayDirectory = "checkpoint_arrays";

// One self-contained checkpoint (every array inside `file`). input_name: the name the run file
// was read under (kept for the resumed run's metadata).
void write_checkpoint(const std::filesystem::path& file, const ProtocolState& state,
                      const ProtocolRunner& runner, std::string_view input_toml,
                      std::string_view input_name);

// Reads a checkpoint (self-contained or with array files) written for this runner's run file.
// Throws std::runtime_error if a file is unreadable, was written for a different run file
// (input_toml differs) or does not match the system's sizes.
ProtocolState read_checkpoint(const std::filesystem::path& file, const ProtocolRunner& runner,
                              std::string_view input_toml);

// A run's checkpoints in `directory` (its staging directory): the index kCheckpointFile and the
// array files in kArrayDirectory, which belong to the writer. Only one writer per directory.
class CheckpointWriter {
 public:
  explicit CheckpointWriter(std::filesystem::path directory);

  // Whether the directory holds a checkpoint to continue from.
  [[nodiscard]] bool exists() const;
  // Reads it (read_checkpoint) and takes over its array files, so that the next write() writes
  // only what changes; removes array files the index does not name (left by a run killed while
  // writing). Throws as read_checkpoint.
  ProtocolState read(const ProtocolRunner& runner, std::string_view input_toml);
  // Writes the checkpoint of `state`: the node arrays whose value changed since the last write
  // (KeptPositions::version, the anchor's identity) to new array files, then the index; then
  // removes the array files the new index no longer names. Throws std::runtime_error (the file
  // and the reason, e.g. a full disk); the previous checkpoint then stays as it was.
  void write(const ProtocolState& state, const ProtocolRunner& runner, std::string_view input_toml,
             std::string_view input_name);
  // Removes the checkpoint (the index, then the array files and their directory): the run's
  // results are complete. Does not throw; what cannot be removed stays.
  void remove();

  // The array files the current index names (for tests).
  [[nodiscard]] std::map<std::string, std::string> array_files() const;

 private:
  struct ArrayFile {
    std::uint64_t version = 0;  // KeptPositions::version of the array written
    std::string file;           // in kArrayDirectory
  };

  std::filesystem::path directory_;
  std::map<std::string, ArrayFile> written_;  // by the array's path in the index
  // The anchor the index's anchor file holds (not keeping it alive: a new one is a new object).
  std::weak_ptr<const mess::PreconditionerAnchor> anchor_written_;
};

}  // namespace mresim::mess_protocol
