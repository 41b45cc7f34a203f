#pragma once

// Small lattices and finite-difference helpers for the tests of src/mresim/mess.

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <functional>
#include <random>
#include <vector>

#include "finite_differences.hpp"
#include "mresim/core/constants.hpp"
#include "mresim/mess/lattice/lattice.hpp"
#include "mresim/mess/profile/model_profile.hpp"

namespace mresim::mess::testing {

// A box of cells[0] x cells[1] x cells[2] cells with particles of order n_d centred in the
// given cells (cell coordinates of each particle's centre voxel).
inline lattice::Lattice small_lattice(const mess::ModelProfile& profile, std::array<int, 3> cells,
                                      const std::vector<std::array<int, 3>>& centre_cells = {},
                                      int discretization_order = 1, double poisson_ratio = 0.47) {
  lattice::LatticeSpec spec;
  profile.apply_to(spec);
  spec.poisson_ratio = poisson_ratio;
  spec.discretization_order = discretization_order;
  const double l_e = lattice::element_length(spec.particle_radius, discretization_order);
  lattice::ByHandPlacement placement;
  placement.box.lengths = Eigen::Vector3d(cells[0], cells[1], cells[2]) * l_e;
  for (const auto& c : centre_cells) {
    placement.positions.emplace_back((c[0] + 0.5) * l_e, (c[1] + 0.5) * l_e, (c[2] + 0.5) * l_e);
  }
  spec.placement = placement;
  return lattice::build_lattice(spec);
}

// Positions moved by uniform random amounts in [-amplitude, amplitude] (m), fixed seed.
inline Eigen::Matrix3Xd perturbed(const Eigen::Matrix3Xd& x, double amplitude,
                                  std::uint32_t seed = 7) {
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> u(-amplitude, amplitude);
  Eigen::Matrix3Xd y = x;
  for (Eigen::Index k = 0; k < y.size(); ++k) y.data()[k] += u(gen);
  return y;
}

inline std::vector<Eigen::Index> all_coordinates(const Eigen::Matrix3Xd& x) {
  std::vector<Eigen::Index> k(static_cast<std::size_t>(x.size()));
  for (Eigen::Index i = 0; i < x.size(); ++i) k[static_cast<std::size_t>(i)] = i;
  return k;
}

// max |a_k - b_k| / max |b_k| over the listed coordinates of a.
inline double relative_error(const Eigen::Matrix3Xd& a, const std::vector<Eigen::Index>& coords,
                             const std::vector<double>& b) {
  double diff = 0.0;
  double scale = 0.0;
  for (std::size_t i = 0; i < coords.size(); ++i) {
    diff = std::max(diff, std::abs(a.data()[coords[i]] - b[i]));
    scale = std::max(scale, std::abs(b[i]));
  }
  return diff / scale;
}

inline Eigen::Vector3d tesla(double bx, double by, double bz) {
  return Eigen::Vector3d(bx, by, bz) / kMu0;
}

}  // namespace mresim::mess::testing
