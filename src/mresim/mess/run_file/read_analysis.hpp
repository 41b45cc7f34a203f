#pragma once

// [analysis] of a 3D run file (docs/run-files-3d.md): settings of what the outputs derive from
// the relaxed states. Read after [particles] (the defaults depend on the particle radius).

#include <optional>

#include "mresim/config/table_reader.hpp"
#include "mresim/mess/run_file/mess_spec.hpp"

namespace mresim::mess_config {

// cluster_distance (m, centre to centre): finite and >= 2R (touching spheres; nothing closer
// can be a contact the WCA term allows); default the WCA cut-off 2^(1/6)(2R + 100 nm).
// Throws config::ConfigError naming the key, the value and the allowed range.
AnalysisSpec read_analysis(const std::optional<config::TableReader>& table, double particle_radius);

}  // namespace mresim::mess_config
