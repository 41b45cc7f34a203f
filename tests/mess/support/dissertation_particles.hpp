#pragma once

// The dissertation's magnetic particles and configurations of them given in units of their
// radius, for the tests of the magnetization and of the magnetic energy terms.

#include <Eigen/Core>
#include <initializer_list>

#include "../../support/dissertation_values.hpp"
#include "mresim/mess/magnetization/magnetic_particles.hpp"

namespace mresim::mess::testing {

// R = 1.5 um, chi0 = 70, Ms = 1.6e6 A/m.
inline constexpr magnetism::MagneticParticles kParticles{};
static_assert(kParticles.radius == mresim::testing::kR && kParticles.Ms == mresim::testing::kMs);

// Particle centres, one column each, given in units of R.
inline Eigen::Matrix3Xd centres_in_radii(std::initializer_list<Eigen::Vector3d> columns) {
  Eigen::Matrix3Xd c(3, static_cast<Eigen::Index>(columns.size()));
  int k = 0;
  for (const Eigen::Vector3d& v : columns) c.col(k++) = v * kParticles.radius;
  return c;
}

// Well separated particles (>= 3.2 R apart): one solution, the fixed point contracts.
inline const Eigen::Matrix3Xd kLoose =
    centres_in_radii({{0.0, 0.0, 0.0}, {3.4, 0.5, -0.3}, {-0.8, 3.3, 1.0}, {1.2, -1.1, 3.5}});

}  // namespace mresim::mess::testing
