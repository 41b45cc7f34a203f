#pragma once

// What the load protocols (strain_protocol.cpp, stress_protocol.cpp) share: reading the axes and
// the values of a [strain] or [stress] table, and describing them for `mresim info`
// (docs/run-files-3d.md, "[strain]" and "[stress]").

#include <string>
#include <vector>

#include "mresim/app/info_report.hpp"
#include "mresim/config/table_reader.hpp"
#include "mresim/mess/run_file/mess_spec.hpp"

namespace mresim::mess_protocol::load_tables {

// The axis names "x", "y", "z" (0, 1, 2).
const std::vector<std::string>& axes();
int axis_index(const std::string& name);
const char* axis_name(int axis);

// The value as written, or `fallback` (a default) when the key is absent.
std::string text_or(const config::TableReader& t, std::string_view key,
                    const std::string& fallback);

// A key that another key needs: "strain.steps = (missing): strain.max needs ...".
[[noreturn]] void needed(const config::TableReader& t, std::string_view key,
                         const std::string& what);

struct LoadAxes {
  int normal = 2;
  int direction = 0;
};

// normal (default "z") and, for shear, direction (default "x", != normal); other kinds act
// along the normal (a direction, if given, must equal it; torsion takes none).
LoadAxes read_axes(const config::TableReader& t, mess_config::LoadKind kind);

// max and steps, or values; the list starts at 0 (the reference state at each field).
std::vector<double> read_load_values(const config::TableReader& t, const config::Range& max_range,
                                     const config::Range& value_range, const std::string& unit,
                                     const std::string& what);

mess_config::LoadKind parse_kind(const std::string& name);

// kind, normal and (shear) direction of a load table's settings.
template <typename Spec>
void describe_axes(const Spec& spec, const std::string& sec, app::InfoReport& r) {
  r.add_text(sec, "kind", mess_config::to_string(spec.kind));
  r.add_text(sec, "normal", axis_name(spec.normal), "loaded faces are normal to this axis");
  if (spec.kind == mess_config::LoadKind::shear) {
    r.add_text(sec, "direction", axis_name(spec.direction), "displacement or traction axis");
  }
}

}  // namespace mresim::mess_protocol::load_tables
