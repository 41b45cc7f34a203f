#pragma once

#include <stdexcept>
#include <string>

namespace mresim::config {

// Raised for anything wrong in a run file: syntax, missing or unknown keys, wrong types, values
// out of range. The message is one line that names the key, the value and what is allowed, so
// the command line can print it as is ("mresim: error: <message>") and exit with status 2.
struct ConfigError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

}  // namespace mresim::config
