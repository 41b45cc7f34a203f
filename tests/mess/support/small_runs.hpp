#pragma once

// Small 3D run files (seconds) for the protocol tests: two particles of order n_d = 1
// (l_e = 1 um) along z in a 9 x 9 x 17 um box, 7 um apart, physical profile.

#include <string>

#include "mresim/config/table_reader.hpp"
#include "mresim/mess/run_file/mess_spec.hpp"

namespace mresim::mess_protocol::testing {

inline const char* const kSmallModel = R"(
[model]
profile = "physical"
discretization_order = 1

[particles]
placement = "chain"
count = 2
separation = 7e-6
axis = "z"

[box]
size = [9e-6, 9e-6, 17e-6]
)";

// mess_hysteresis over 0 -> max -> -max -> max with `steps` increments of max/steps.
inline std::string small_hysteresis(double max_tesla, int steps, int checkpoint_every = 1) {
  return std::string("[run]\ntype = \"mess_hysteresis\"\n") + kSmallModel +
         "\n[field]\nmax = " + std::to_string(max_tesla) + "\nsteps = " + std::to_string(steps) +
         "\n\n[output]\ncheckpoint_every = " + std::to_string(checkpoint_every) + "\n";
}

// mess_strain at three fields x three shear strains: the steps go through the fields at each
// strain, so each field's latest state and zero-load reference wait while the others relax.
inline std::string three_field_shear() {
  return std::string("[run]\ntype = \"mess_strain\"\n") + kSmallModel +
         "\n[field]\nmagnitudes = [0.0, 0.05, 0.1]\n"
         "\n[strain]\nkind = \"shear\"\nnormal = \"z\"\ndirection = \"x\"\n"
         "max = 0.02\nsteps = 2\n";
}

inline mess_config::MessSpec spec_of(const std::string& toml) {
  return mess_config::read_mess_run_file(config::TableReader::parse_string(toml, "test.toml"));
}

}  // namespace mresim::mess_protocol::testing
