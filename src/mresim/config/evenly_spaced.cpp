#include "mresim/config/evenly_spaced.hpp"

#include <fmt/format.h>

#include <cstdlib>
#include <string>

namespace mresim::config {

namespace {

// 15 significant digits: every such decimal survives a round trip through a double, so the
// result is the double a user typing that decimal would get.
double nearest_to_15_digit_decimal(double x) {
  const std::string text = fmt::format("{:.15g}", x);
  return std::strtod(text.c_str(), nullptr);
}

}  // namespace

std::vector<double> evenly_spaced_from_zero(double max, long steps) {
  std::vector<double> out;
  out.reserve(static_cast<std::size_t>(steps) + 1);
  for (long i = 0; i <= steps; ++i) {
    const double raw = max * static_cast<double>(i) / static_cast<double>(steps);
    out.push_back(i == steps ? max : nearest_to_15_digit_decimal(raw));
  }
  return out;
}

}  // namespace mresim::config
