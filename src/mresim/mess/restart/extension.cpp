#include "mresim/mess/restart/extension.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "mresim/config/config_error.hpp"

namespace mresim::mess_protocol {

namespace {

constexpr double kRelative = 1e-12;

bool close(double a, double b) {
  return std::abs(a - b) <= kRelative * std::max(std::abs(a), std::abs(b));
}

bool same_values(const StepSpec& a, const StepSpec& b) {
  return close(a.field.x(), b.field.x()) && close(a.field.y(), b.field.y()) &&
         close(a.field.z(), b.field.z()) && close(a.load_value, b.load_value);
}

bool has_values_of(const std::vector<StepSpec>& plan, const StepSpec& step) {
  return std::any_of(plan.begin(), plan.end(),
                     [&](const StepSpec& s) { return same_values(s, step); });
}

}  // namespace

bool same_step(const StepSpec& a, const StepSpec& b) {
  return a.field_index == b.field_index && a.load_index == b.load_index && same_values(a, b);
}

Extension plan_extension(const std::vector<StepSpec>& computed,
                         const std::vector<StepSpec>& extended, const std::string& what) {
  Extension e;
  while (e.shared < computed.size() && e.shared < extended.size() &&
         same_step(computed[e.shared], extended[e.shared])) {
    ++e.shared;
  }
  for (const StepSpec& s : computed) {
    if (has_values_of(extended, s)) continue;
    throw config::ConfigError(fmt::format(
        "extend {}: the extended protocol has no step with the field ({:g}, {:g}, {:g}) T and "
        "load {:g} of computed step {}; extend keeps the computed steps and only adds fields or "
        "load values (raise max and steps together so that the old values stay)",
        what, s.field.x(), s.field.y(), s.field.z(), s.load_value, s.index));
  }
  for (const StepSpec& s : extended) {
    if (!has_values_of(computed, s)) e.added.push_back(static_cast<std::int64_t>(s.index));
  }
  if (e.added.empty()) {
    throw config::ConfigError(fmt::format(
        "extend {}: adds no field or load value to the {} computed steps", what, computed.size()));
  }
  for (std::size_t k = e.shared; k < computed.size(); ++k) {
    e.replaced.push_back(static_cast<std::int64_t>(k));
  }
  return e;
}

}  // namespace mresim::mess_protocol
