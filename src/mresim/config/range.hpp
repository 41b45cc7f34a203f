#pragma once

#include <optional>
#include <string>

namespace mresim::config {

// The set of values a numeric key accepts: an interval with optional, inclusive or exclusive
// bounds. Validation and the error text come from the same object, so a message can never
// disagree with the check that produced it.
struct Range {
  std::optional<double> min;
  std::optional<double> max;
  bool min_inclusive = true;
  bool max_inclusive = true;

  static Range any() { return {}; }
  static Range positive() { return above(0.0); }
  static Range non_negative() { return at_least(0.0); }
  static Range at_least(double a) { return {a, std::nullopt, true, true}; }
  static Range above(double a) { return {a, std::nullopt, false, true}; }
  static Range at_most(double b) { return {std::nullopt, b, true, true}; }
  static Range below(double b) { return {std::nullopt, b, true, false}; }
  static Range between(double a, double b) { return {a, b, true, true}; }  // [a, b]
  static Range open(double a, double b) { return {a, b, false, false}; }   // (a, b)

  // False for NaN whatever the bounds.
  [[nodiscard]] bool contains(double x) const;

  // "must be > 0", "must be in [0, 90]", "must be < 1"; "may be any number" for any().
  [[nodiscard]] std::string describe() const;
};

}  // namespace mresim::config
