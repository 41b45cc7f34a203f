#pragma once

#include <string>

namespace mresim::app {

// The command line the program was started with, recorded in results.h5 (io/metadata.hpp).
// main() sets it once, before any run; library use (the tests) leaves it empty.
void set_command_line(int argc, const char* const* argv);
// The arguments joined by spaces, each quoted for a POSIX shell where it needs it, so that
// the line can be pasted back into a shell: `mresim run 'my run.toml' --set 'field.max=0.1'`.
// "" when set_command_line was not called.
const std::string& command_line();

// One argument quoted for a POSIX shell: as it is when it holds only characters a shell leaves
// alone, otherwise in single quotes (a ' inside becomes '\'').
std::string shell_quoted(const std::string& argument);

}  // namespace mresim::app
