#pragma once

// Checkpoints of 3D runs: the whole ProtocolState (the latest state at every field, the
// zero-load references, the records of the steps done) plus the run file it belongs to, so that
// `mresim resume` continues a killed run and ends with the same results as an uninterrupted one.
//
// A checkpoint is written to "<file>.tmp" and renamed over <file>: a run killed while writing
// leaves the previous checkpoint intact.

#include <filesystem>
#include <string>
#include <string_view>

#include "mresim/mess/protocols/protocol_runner.hpp"

namespace mresim::mess_protocol {

inline constexpr const char* kCheckpointFile = "checkpoint.h5";

// input_name: the name the run file was read under (kept for the resumed run's metadata).
void write_checkpoint(const std::filesystem::path& file, const ProtocolState& state,
                      const ProtocolRunner& runner, std::string_view input_toml,
                      std::string_view input_name);

// Reads a checkpoint written for this runner's run file. Throws std::runtime_error if the
// file is unreadable, was written for a different run file (input_toml differs) or does not
// match the system's sizes.
ProtocolState read_checkpoint(const std::filesystem::path& file, const ProtocolRunner& runner,
                              std::string_view input_toml);

}  // namespace mresim::mess_protocol
