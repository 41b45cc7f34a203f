#include "mresim/config/range.hpp"

#include <fmt/format.h>

#include <cmath>

namespace mresim::config {

bool Range::contains(double x) const {
  if (std::isnan(x)) return false;
  if (min && (min_inclusive ? x < *min : x <= *min)) return false;
  if (max && (max_inclusive ? x > *max : x >= *max)) return false;
  return true;
}

std::string Range::describe() const {
  // fmt's "{}" prints the shortest text that reads back to the same double: 90, 0.5, 1e-06.
  if (min && max) {
    return fmt::format("must be in {}{}, {}{}", min_inclusive ? '[' : '(', *min, *max,
                       max_inclusive ? ']' : ')');
  }
  if (min) return fmt::format("must be {} {}", min_inclusive ? ">=" : ">", *min);
  if (max) return fmt::format("must be {} {}", max_inclusive ? "<=" : "<", *max);
  return "may be any number";
}

}  // namespace mresim::config
