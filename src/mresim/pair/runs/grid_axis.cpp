#include "mresim/pair/runs/grid_axis.hpp"

#include <fmt/format.h>

#include <cmath>

namespace mresim::pair::runs {

using config::Range;

std::vector<double> read_grid_axis(const config::TableReader& t, const std::string& name,
                                   const Range& allowed, const std::string& unit,
                                   const std::string& default_spacing) {
  const std::string values_key = name + "_values";
  const std::string min_key = name + "_min";
  const std::string max_key = name + "_max";
  const std::string count_key = name + "_count";
  const std::string spacing_key = name + "_spacing";
  const bool explicit_values = t.has(values_key);
  // Read every key so that both forms are known; then insist on exactly one form.
  const auto values = t.optional_number_list(values_key, allowed, unit, 1);
  const auto lo = t.optional_number(min_key, allowed, unit);
  const auto hi = t.optional_number(max_key, allowed, unit);
  const long count = t.integer_or(count_key, 0, Range::between(0, 100000));
  const std::string spacing = t.choice_or(spacing_key, default_spacing, {"linear", "log"});
  if (explicit_values) {
    if (lo || hi || count > 0) {
      t.fail(values_key, t.value_text(values_key),
             fmt::format("give either {} or {}, {} and {}, not both", values_key, min_key, max_key,
                         count_key));
    }
    return *values;
  }
  if (!lo || !hi || count == 0) {
    t.fail(count_key, t.value_text(count_key).empty() ? "(missing)" : t.value_text(count_key),
           fmt::format("the {} axis needs {}, {} and {} >= 1 (or {} = [...])", name, min_key,
                       max_key, count_key, values_key));
  }
  if (*hi < *lo) t.fail(max_key, *hi, fmt::format("must be >= {} = {}", min_key, *lo));
  if (spacing == "log" && *lo <= 0.0) {
    t.fail(min_key, *lo, "must be > 0 for log spacing");
  }
  std::vector<double> out;
  for (long i = 0; i < count; ++i) {
    const double f = count == 1 ? 0.0 : static_cast<double>(i) / static_cast<double>(count - 1);
    out.push_back(spacing == "log" ? *lo * std::pow(*hi / *lo, f) : *lo + f * (*hi - *lo));
  }
  return out;
}

}  // namespace mresim::pair::runs
