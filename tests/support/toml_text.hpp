#pragma once

// Run-file text written in a test, read as the run-file readers see it.

#include <string>

#include "mresim/config/table_reader.hpp"

namespace mresim::testing {

// The TableReader of `text` (named test.toml).
inline config::TableReader parse(const std::string& text) {
  return config::TableReader::parse_string(text, "test.toml");
}

}  // namespace mresim::testing
