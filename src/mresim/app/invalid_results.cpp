#include "mresim/app/invalid_results.hpp"

#include <cmath>

namespace mresim::app {

void ResultCheck::flag(std::string_view quantity, std::string_view where) {
  if (count_ < kListed) {
    if (!listed_.empty()) listed_ += "; ";
    listed_ += std::string(quantity) + " at " + std::string(where);
  }
  ++count_;
}

bool ResultCheck::finite(double value, std::string_view quantity, std::string_view where) {
  if (std::isfinite(value)) return true;
  flag(quantity, where);
  return false;
}

std::string ResultCheck::message(std::string_view hint) const {
  std::string out = what_ + ": " + listed_;
  if (count_ > kListed) out += ", and " + std::to_string(count_ - kListed) + " more";
  if (!hint.empty()) out += " (" + std::string(hint) + ")";
  return out;
}

void ResultCheck::throw_if_any(std::string_view hint) const {
  if (any()) throw InvalidResults(message(hint));
}

}  // namespace mresim::app
