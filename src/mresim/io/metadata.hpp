#pragma once

#include <string>

#include "mresim/config/table_reader.hpp"
#include "mresim/io/hdf5_file.hpp"

namespace mresim::io {

// Records what is needed to reproduce a run as attributes of the root group of results.h5:
//   mresim_version  program version (mresim::kVersion)
//   mresim_git      `git describe --always --dirty` of the source tree at build time,
//                   "unknown" when it was not built from a git checkout
//   host_name       the machine that ran it
//   command_line    the mresim command as typed (app::command_line(), shell-quoted); "" when
//                   the run was started by library code rather than the mresim command
//   run_type        [run].type
//   input_toml      the complete run file, byte for byte; with --set overrides the effective
//                   run file (the overridden table as toml++ writes it), which is what ran
//   input_file      the name the run file was read under
//   created_utc     ISO 8601 time stamp, e.g. 2025-01-31T14:05:09Z
// and, only when there are --set overrides (so that a plain run's metadata is unchanged):
//   input_overrides the KEY=VALUE arguments in the order applied, one per line
//   input_file_toml the run file as written, byte for byte
void write_run_metadata(Hdf5File& file, const config::TableReader& root,
                        const std::string& run_type);

// This machine's host name ("unknown" if it has none).
std::string host_name();

// The current time as "YYYY-MM-DDTHH:MM:SSZ".
std::string utc_timestamp();

}  // namespace mresim::io
