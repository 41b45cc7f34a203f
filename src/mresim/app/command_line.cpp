#include "mresim/app/command_line.hpp"

#include <string_view>

namespace mresim::app {

namespace {

std::string& command_line_storage() {
  static std::string line;
  return line;
}

bool needs_no_quotes(const std::string& argument) {
  constexpr std::string_view kSafe =
      "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_-+=.,/:@%";
  return !argument.empty() && argument.find_first_not_of(kSafe) == std::string::npos;
}

}  // namespace

std::string shell_quoted(const std::string& argument) {
  if (needs_no_quotes(argument)) return argument;
  std::string out = "'";
  for (const char c : argument) {
    if (c == '\'') {
      out += "'\\''";
    } else {
      out += c;
    }
  }
  return out + "'";
}

void set_command_line(int argc, const char* const* argv) {
  std::string line;
  for (int i = 0; i < argc; ++i) {
    if (i > 0) line += ' ';
    line += shell_quoted(argv[i]);
  }
  command_line_storage() = line;
}

const std::string& command_line() { return command_line_storage(); }

}  // namespace mresim::app
