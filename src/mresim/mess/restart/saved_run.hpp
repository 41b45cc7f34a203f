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
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include "mresim/mess/protocols/kept_positions.hpp"
#include "mresim/mess/protocols/protocol_runner.hpp"

namespace mresim::mess_protocol {

// In a finished run's directory: the protocol state after its last step (checkpoint format).
inline constexpr const char* kFinalStateFile = "final_state.h5";

// One step's kept positions in a saved run: its step file (positions/step_NNNNNN.h5), read
// only when asked for, or an array held here (from the final state, parked in the scratch file
// where the runner that read it has a scratch directory; or a rerun's new result). So reading a
// run holds none of its step files in memory: at full size a step's positions are 7 MB (the
// Fig. 4.11 pair) to 24 MB (the Fig. 4.25 helix, 132 steps).
class SavedPositions {
 public:
  SavedPositions() = default;
  explicit SavedPositions(std::filesystem::path step_file) : file_(std::move(step_file)) {}
  explicit SavedPositions(KeptPositions kept) : kept_(std::move(kept)) {}

  // The array (3 x N): read from the step file, or a copy of the one held.
  [[nodiscard]] Eigen::Matrix3Xd load() const;
  // Whether load() reads a step file.
  [[nodiscard]] bool in_step_file() const { return !file_.empty(); }

 private:
  std::filesystem::path file_;
  KeptPositions kept_;
};

struct SavedRun {
  std::vector<StepSpec> steps;                      // the run's plan
  std::vector<StepRecord> records;                  // every step's record
  std::map<std::size_t, SavedPositions> positions;  // by step, where kept
  bool has_final_state = false;
  // Where the multilevel preconditioner kept after the last step was built (final_state.h5;
  // ProtocolState::preconditioner_anchor); null: none, or no final state.
  std::shared_ptr<const mess::PreconditionerAnchor> final_anchor;
};

// Reads the run in `dir` (results.h5, final_state.h5; of positions/ only which steps have a
// file). `runner` is built from the run's own run file `input_toml` (results.h5's
// /@input_toml); the final state's arrays are parked where it parks them. Throws
// std::runtime_error when the files do not belong to that run file.
SavedRun read_saved_run(const std::filesystem::path& dir, const ProtocolRunner& runner,
                        const std::string& input_toml);

// The state `runner` has after the first `count` steps of `saved` (which must be its first
// `count` steps too), or nothing when a position it needs was not kept. Its arrays are read one
// at a time and parked where `runner` parks them (ProtocolRunner::park_kept_positions).
std::optional<ProtocolState> state_after(const SavedRun& saved, const ProtocolRunner& runner,
                                         std::size_t count);

// What follows the state after `count` steps where last_restorable looks for one: a step the
// run goes on with as a run of the runner's file would (extend), which must keep or build the
// multilevel preconditioner as that run did; or one relaxed afresh with its own (rerun).
enum class NextStep { as_the_run, afresh };

// The largest k <= count whose state_after is available (0 always is) and from which the steps
// up to `count` continue as the saved run did, step `count` itself as `next` says: where the
// saved run kept its multilevel preconditioner from an earlier step, a state is taken only
// where the preconditioner's anchor is known (the final state) or not needed (the next step
// built its own), so that the continued steps are the saved run's bit for bit.
std::size_t last_restorable(const SavedRun& saved, const ProtocolRunner& runner, std::size_t count,
                            NextStep next);

// A kept file of the finished run into the staging directory: a hard link (mresim never writes
// these files in place, it replaces them), a copy where links are not possible.
void carry_kept_file(const std::filesystem::path& from, const std::filesystem::path& to);

}  // namespace mresim::mess_protocol
