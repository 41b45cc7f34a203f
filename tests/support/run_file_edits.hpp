#pragma once

// Invalid run files made by editing a valid one, for the tests of the run-file readers'
// messages.

#include <ostream>
#include <stdexcept>
#include <string>

namespace mresim::testing {

// `text` with the first occurrence of `from` replaced by `to`.
inline std::string edit(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  if (at == std::string::npos) throw std::logic_error("no " + from);
  return text.replace(at, from.size(), to);
}

// A named invalid run file and the message it must give.
struct BadInput {
  std::string name;
  std::string text;
  std::string message;
};

// Names the case in test output instead of dumping the struct's bytes.
inline void PrintTo(const BadInput& input, std::ostream* os) { *os << input.name; }

}  // namespace mresim::testing
