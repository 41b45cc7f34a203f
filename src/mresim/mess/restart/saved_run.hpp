#pragma once

// What a finished 3D run keeps that `mresim extend` and `mresim rerun` start from, and the
// protocol state after any of its steps rebuilt from it (docs/outputs-3d.md#final-state).
//
// A run's state after step k (protocol_runner.hpp) is, per slot, the positions and
// magnetizations of the latest step in that slot, plus the zero-load positions per field. The
// magnetizations of every step are in the records; positions are kept
//  - for the steps whose results the final state holds, in final_state.h5 (the last checkpoint,
//    written when the run ends, [output] keep_final_state), and
//  - for every step with [output] node_positions = true (positions/step_NNNNNN.h5).
// So the state after the last step is always there, the state after an earlier step when the
// positions of the steps it needs were kept.

#include <Eigen/Core>
#include <filesystem>
#include <map>
#include <optional>
#include <vector>

#include "mresim/mess/protocols/protocol_runner.hpp"

namespace mresim::mess_protocol {

// In a finished run's directory: the protocol state after its last step (checkpoint format).
inline constexpr const char* kFinalStateFile = "final_state.h5";

struct SavedRun {
  std::vector<StepSpec> steps;                        // the run's plan
  std::vector<StepRecord> records;                    // every step's record
  std::map<std::size_t, Eigen::Matrix3Xd> positions;  // by step, where kept
  bool has_final_state = false;
};

// Reads the run in `dir` (results.h5, final_state.h5, positions/). `runner` is built from the
// run's own run file `input_toml` (results.h5's /@input_toml). Throws std::runtime_error when
// the files do not belong to that run file.
SavedRun read_saved_run(const std::filesystem::path& dir, const ProtocolRunner& runner,
                        const std::string& input_toml);

// The state `runner` has after the first `count` steps of `saved` (which must be its first
// `count` steps too), or nothing when a position it needs was not kept.
std::optional<ProtocolState> state_after(const SavedRun& saved, const ProtocolRunner& runner,
                                         std::size_t count);

// The largest k <= count whose state_after is available (0 always is).
std::size_t last_restorable(const SavedRun& saved, const ProtocolRunner& runner, std::size_t count);

// A kept file of the finished run into the staging directory: a hard link (mresim never writes
// these files in place, it replaces them), a copy where links are not possible.
void carry_kept_file(const std::filesystem::path& from, const std::filesystem::path& to);

}  // namespace mresim::mess_protocol
