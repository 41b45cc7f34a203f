#pragma once

// Reproducible random numbers for the Preisach relay population (Fig. 1.5).
// std::normal_distribution and the other std distributions are implemented differently by
// each standard library, so identical seeds would give different relays on different
// platforms. std::mt19937_64 itself is fully specified by the standard; on top of it this
// class uses only explicitly written transforms (53-bit uniforms and Box-Muller).

#include <cstdint>
#include <random>

namespace mresim::magnetism {

class PortableNormal {
 public:
  explicit PortableNormal(std::uint64_t seed);

  // Uniform double in (0, 1]: ((x >> 11) + 1) * 2^-53 for one 64-bit engine output x.
  double uniform_open();

  // Standard normal deviate by the Box-Muller transform: each pair of uniforms (u1, u2)
  // gives r cos(2 pi u2) and then r sin(2 pi u2), r = sqrt(-2 ln u1).
  double standard_normal();

  // mean + sd * standard_normal().
  double normal(double mean, double sd);

  // Fair coin from the top bit of one engine output.
  bool coin();

 private:
  std::mt19937_64 engine_;
  bool has_spare_ = false;
  double spare_ = 0.0;
};

}  // namespace mresim::magnetism
