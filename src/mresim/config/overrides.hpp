#pragma once

// `--set KEY=VALUE` (mresim run/info, docs/cli.md): one run file, many variants without edited
// copies. Each argument is applied to the parsed TOML table before any validation, so an
// overridden value is checked exactly as if it had been written in the file (same keys, same
// ranges, same messages, unknown keys refused).
//
// KEY   a dotted path of bare TOML keys (letters, digits, '_' and '-'), each optionally indexing
//       an existing array: field.max, solver.magnetization.tolerance, case[1].penalty.type.
//       Missing tables on the way are created; an existing value on the way that is not a table
//       is an error.
// VALUE a TOML value (0.05, 1e-6, "seed", [1, 1, 2], true, {a = 1}); a bare word that is not
//       valid TOML is taken as a string (model.profile=seed). A value that starts like a
//       string, array or inline table (", ', [, {) must be valid TOML.
//
// Every error is a ConfigError naming the option and the argument:
//   "--set: field.max.x=1: field.max is a float (1.0), not a table".

#include <toml++/toml.h>

#include <string>
#include <string_view>
#include <vector>

namespace mresim::config {

// Checks the form of one argument (KEY=VALUE, the key's syntax, the value's syntax) without a
// table: "" when it is well formed, else the message without the option name
// ("fieldmax: expected KEY=VALUE, e.g. field.max=0.5"). The command line calls it while it
// parses its options, so a malformed --set is refused before the run file is read.
[[nodiscard]] std::string override_syntax_error(std::string_view argument);

// Applies the arguments to `root` in order (a later one for the same key wins). Throws
// ConfigError for a malformed argument or a key whose parent is not a table.
void apply_overrides(toml::table& root, const std::vector<std::string>& arguments);

// `root` as TOML text (toml++'s formatter, full float precision), the "effective run file" that
// is validated and recorded when there are overrides. Parsing it gives `root` back.
[[nodiscard]] std::string toml_text(const toml::table& root);

// `text` as a TOML basic string: in double quotes, with ", \ and control characters escaped
// (defined in table_reader.cpp, whose messages show string values this way).
[[nodiscard]] std::string toml_string_literal(std::string_view text);

}  // namespace mresim::config
