#include "mresim/magnetism/portable_random.hpp"

#include <cmath>
#include <numbers>

namespace mresim::magnetism {

PortableNormal::PortableNormal(std::uint64_t seed) : engine_(seed) {}

double PortableNormal::uniform_open() {
  constexpr double kTwoToMinus53 = 1.0 / 9007199254740992.0;
  return static_cast<double>((engine_() >> 11) + 1) * kTwoToMinus53;
}

double PortableNormal::standard_normal() {
  if (has_spare_) {
    has_spare_ = false;
    return spare_;
  }
  const double u1 = uniform_open();  // in (0, 1], so log(u1) is finite
  const double u2 = uniform_open();
  const double radius = std::sqrt(-2.0 * std::log(u1));
  const double angle = 2.0 * std::numbers::pi * u2;
  spare_ = radius * std::sin(angle);
  has_spare_ = true;
  return radius * std::cos(angle);
}

double PortableNormal::normal(double mean, double sd) { return mean + sd * standard_normal(); }

bool PortableNormal::coin() { return (engine_() >> 63) != 0; }

}  // namespace mresim::magnetism
