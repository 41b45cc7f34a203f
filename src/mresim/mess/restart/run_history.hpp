#pragma once

// The /history group of a 3D run's results.h5: one entry per `mresim extend` or `mresim rerun`
// that changed the run after it was first made (docs/outputs-3d.md#history). Each new results.h5
// carries the entries of the one it replaces, so the list is the run's whole story.
//
// Layout: /history with attribute `entries` (the count); entry i is the group /history/<i> with
// string attributes kind, time_utc, command_line, overrides (one KEY=VALUE per line),
// mresim_version, previous_input_toml; int datasets added_steps, recomputed_steps,
// replaced_steps; and, when steps were replaced, their records as they were before under
// /history/<i>/replaced (the layout of /steps).

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "mresim/io/hdf5_file.hpp"
#include "mresim/io/hdf5_reader.hpp"
#include "mresim/mess/protocols/protocol_runner.hpp"

namespace mresim::mess_protocol {

struct HistoryEntry {
  std::string kind;  // "extend" or "rerun"
  std::string time_utc;
  std::string command_line;
  std::vector<std::string> overrides;  // the --set arguments of this command
  std::string mresim_version;
  std::string previous_input_toml;             // the effective run file before this command
  std::vector<std::int64_t> added_steps;       // steps the run did not have before
  std::vector<std::int64_t> recomputed_steps;  // steps computed again (rerun: the step K)
  std::vector<std::int64_t> replaced_steps;    // earlier results no longer in /steps
  std::vector<StepRecord> replaced;            // their records, as they were
};

// Writes `entries` as /history of `file` (nothing when there are none). `runner` gives the
// particle count, the load unit and the energy terms of the records.
void write_history(io::Hdf5File& file, const std::vector<HistoryEntry>& entries,
                   const ProtocolRunner& runner);

// The entries of /history in `file` (none if it has no /history).
std::vector<HistoryEntry> read_history(const io::Hdf5Reader& file, const ProtocolRunner& runner);

// While an extend computes, the history its results will carry waits in this file of the
// staging directory (so that `mresim resume` of an interrupted extend keeps it too).
inline constexpr const char* kPendingHistoryFile = ".mresim-history.h5";

void write_pending_history(const std::filesystem::path& staging_dir,
                           const std::vector<HistoryEntry>& entries, const ProtocolRunner& runner);

// Copies a pending history of `staging_dir` into `results` and removes the file; nothing when
// there is none.
void publish_pending_history(const std::filesystem::path& staging_dir, io::Hdf5File& results,
                             const ProtocolRunner& runner);

// "mresim extend out --set field.max=0.1" from a command's words.
std::string command_line_text(const std::vector<std::string>& words);

}  // namespace mresim::mess_protocol
