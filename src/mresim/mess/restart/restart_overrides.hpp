#pragma once

// Which --set keys `mresim extend` and `mresim rerun` accept (docs/cli.md). Both continue a
// finished run, so neither may change the system its steps were computed for:
//  - extend: only the keys that say how far the field or load sequence goes (field.max,
//    field.steps, field.magnitudes, field.values, field.sequence, and max, steps, values of
//    [strain] and [stress]); whether the new sequence keeps every computed step is checked on
//    the planned steps (extension.hpp);
//  - rerun: only solver settings (solver.*), which decide how a step is relaxed, not what it is.
// A refused key is a config::ConfigError naming the argument, the key and what is allowed.

#include <string>
#include <vector>

namespace mresim::mess_protocol {

// The KEY of "KEY=VALUE".
std::string override_key(const std::string& argument);

void check_extend_overrides(const std::vector<std::string>& overrides);
void check_rerun_overrides(const std::vector<std::string>& overrides);

// "--set a=1 --set b=2" for messages.
std::string overrides_text(const std::vector<std::string>& overrides);

}  // namespace mresim::mess_protocol
