#include "mresim/mess/analysis/box_strain.hpp"

#include <array>
#include <stdexcept>
#include <vector>

#include "mresim/mess/lattice/grid.hpp"

namespace mresim::mess_analysis {

namespace {

// Mean coordinate `axis` of the nodes `nodes` at positions x.
double mean_coordinate(const Eigen::Matrix3Xd& x, const std::vector<int>& nodes, int axis) {
  double sum = 0.0;
  for (const int n : nodes) sum += x(axis, n);
  return sum / static_cast<double>(nodes.size());
}

}  // namespace

Eigen::Vector3d box_strain(const lattice::Lattice& lattice, const Eigen::Matrix3Xd& positions) {
  if (positions.cols() != lattice.positions.cols()) {
    throw std::invalid_argument("box_strain: positions do not match the lattice's node count");
  }
  using lattice::Face;
  constexpr std::array<std::array<Face, 2>, 3> kFaces = {
      {{Face::left, Face::right}, {Face::front, Face::back}, {Face::bottom, Face::top}}};
  Eigen::Vector3d e;
  for (int a = 0; a < 3; ++a) {
    const auto& [lower, upper] = kFaces[static_cast<std::size_t>(a)];
    const std::vector<int> lo = lattice::face_nodes(lattice.shape, lower);
    const std::vector<int> hi = lattice::face_nodes(lattice.shape, upper);
    const double now = mean_coordinate(positions, hi, a) - mean_coordinate(positions, lo, a);
    const double initial =
        mean_coordinate(lattice.positions, hi, a) - mean_coordinate(lattice.positions, lo, a);
    e(a) = now / initial - 1.0;
  }
  return e;
}

double strain_along(const Eigen::Vector3d& box_strain, const Eigen::Vector3d& direction) {
  return direction.cwiseAbs2().dot(box_strain);
}

}  // namespace mresim::mess_analysis
