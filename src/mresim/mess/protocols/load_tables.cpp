#include "mresim/mess/protocols/load_tables.hpp"

#include <fmt/format.h>

#include <algorithm>

#include "mresim/config/evenly_spaced.hpp"

// Moved unchanged from run_file/read_mess_spec.cpp (the error messages of the [strain] and
// [stress] tables are those of tests/bad_input/ and tests/mess/run_file/*errors*).

namespace mresim::mess_protocol::load_tables {

using config::Range;
using config::TableReader;
using mess_config::LoadKind;

namespace {
const std::vector<std::string> kAxes{"x", "y", "z"};
}  // namespace

const std::vector<std::string>& axes() { return kAxes; }

int axis_index(const std::string& name) {
  return static_cast<int>(std::find(kAxes.begin(), kAxes.end(), name) - kAxes.begin());
}

const char* axis_name(int a) { return a == 0 ? "x" : a == 1 ? "y" : "z"; }

std::string text_or(const TableReader& t, std::string_view key, const std::string& fallback) {
  const std::string text = t.value_text(key);
  return text.empty() ? fallback : text;
}

void needed(const TableReader& t, std::string_view key, const std::string& what) {
  t.fail(key, "(missing)", what + t.misspelling_hint(key));
}

LoadAxes read_axes(const TableReader& t, LoadKind kind) {
  LoadAxes axes;
  const std::string normal = t.choice_or("normal", "z", kAxes);
  axes.normal = axis_index(normal);
  if (kind == LoadKind::shear) {
    const std::string direction = t.choice_or("direction", "x", kAxes);
    axes.direction = axis_index(direction);
    if (axes.direction == axes.normal) {
      t.fail("direction", text_or(t, "direction", "\"x\" (default)"),
             fmt::format("must differ from {} = \"{}\": shear moves the face normal to {} along "
                         "direction",
                         t.path("normal"), normal, t.path("normal")));
    }
    return axes;
  }
  axes.direction = axes.normal;
  if (!t.has("direction")) return axes;
  if (kind == LoadKind::torsion) {
    t.fail("direction", t.value_text("direction"),
           fmt::format("torsion twists the face normal to {} about that axis; give no "
                       "direction (the sign of the angle sets the sense)",
                       t.path("normal")));
  }
  const std::string direction = t.choice("direction", kAxes);
  if (axis_index(direction) != axes.normal) {
    t.fail("direction", t.value_text("direction"),
           fmt::format("{} acts along the normal {} = \"{}\"; leave direction out or set it "
                       "to \"{}\"",
                       to_string(kind), t.path("normal"), normal, normal));
  }
  return axes;
}

// max and steps, or values; the list starts at 0 (the reference state at each field).
std::vector<double> read_load_values(const TableReader& t, const Range& max_range,
                                     const Range& value_range, const std::string& unit,
                                     const std::string& what) {
  const bool has_max = t.has("max");
  const bool has_steps = t.has("steps");
  const bool has_values = t.has("values");
  const auto max = t.optional_number("max", max_range, unit);
  const long steps = t.integer_or("steps", 0, Range::between(1, 10000));
  const auto values = t.optional_number_list("values", value_range, unit, 1);
  if (has_values && (has_max || has_steps)) {
    t.fail("values", t.value_text("values"),
           fmt::format("give either {0}.values or {0}.max and {0}.steps, not both", t.path()));
  }
  if (has_values) {
    if (values->front() != 0.0) {
      t.fail("values", t.value_text("values"),
             fmt::format("must start with 0: the zero-{} state at each field is the reference "
                         "of the loaded ones (Section 4.2.7)",
                         what));
    }
    return *values;
  }
  if (!has_max) {
    needed(t, "max",
           fmt::format("give {0}.max and {0}.steps, or {0}.values = [0, ...]{1}", t.path(),
                       unit.empty() ? "" : fmt::format(" ({})", unit)));
  }
  if (!has_steps) {
    needed(t, "steps",
           fmt::format("{}.max needs {}.steps, the number of increments from 0 to max "
                       "(integer >= 1)",
                       t.path(), t.path()));
  }
  return config::evenly_spaced_from_zero(*max, steps);
}

LoadKind parse_kind(const std::string& name) {
  if (name == "shear") return LoadKind::shear;
  if (name == "tension") return LoadKind::tension;
  if (name == "compression") return LoadKind::compression;
  return LoadKind::torsion;
}

}  // namespace mresim::mess_protocol::load_tables
