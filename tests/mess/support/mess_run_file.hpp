#pragma once

// Reading 3D run files written in a test, for the tests of the run-file reader and its messages.

#include <string>

#include "mresim/config/config_error.hpp"
#include "mresim/config/table_reader.hpp"
#include "mresim/mess/run_file/mess_spec.hpp"

namespace mresim::testing {

// The MessSpec of the 3D run file `text` (named run.toml).
inline mess_config::MessSpec read_spec(const std::string& text) {
  return mess_config::read_mess_run_file(config::TableReader::parse_string(text, "run.toml"));
}

// The message of the ConfigError that read_spec(text) throws, or "(no error)".
inline std::string spec_error_of(const std::string& text) {
  try {
    (void)read_spec(text);
  } catch (const config::ConfigError& e) {
    return e.what();
  }
  return "(no error)";
}

}  // namespace mresim::testing
