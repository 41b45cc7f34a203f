#include "mresim/mess/distributed/distributed_elastic.hpp"

#include <petscdmda.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "mresim/mess/terms/elastic_formulas.hpp"
#include "mresim/mess/terms/grid_stencil.hpp"

namespace mresim::mess {

namespace {

using Map3 = Eigen::Map<const Eigen::Vector3d>;

using Sums = std::array<double, 4>;

// Per-line partial sums added in line order: the same result for any number of threads.
Sums add_in_order(const std::vector<Sums>& lines) {
  Sums total{};
  for (const Sums& s : lines) {
    for (std::size_t k = 0; k < total.size(); ++k) total[k] += s[k];
  }
  return total;
}

// The cells with a vertex in `owned`: cell corners from one below the owned box to its upper
// end, clipped to the lattice's cells.
NodeBox cells_touching(const NodeBox& owned, const lattice::GridShape& shape) {
  NodeBox cells;
  const std::array<int, 3> cell_count = shape.cells();
  for (std::size_t a = 0; a < 3; ++a) {
    const int lower = std::max(owned.lower[a] - 1, 0);
    const int upper = std::min(owned.lower[a] + owned.size[a], cell_count[a]);
    cells.lower[a] = lower;
    cells.size[a] = std::max(upper - lower, 0);
  }
  return cells;
}

}  // namespace

DistributedElastic::DistributedElastic(const lattice::Lattice& lattice,
                                       const LatticeDecomposition& decomposition,
                                       double volume_force_factor)
    : decomposition_(decomposition),
      kappa_(lattice.polymer.kappa),
      cell_volume_(std::pow(lattice.element_length, 3)),
      volume_factor_(volume_force_factor) {
  const std::array<double, 3> rest_length = elastic::rest_lengths(lattice.element_length);
  for (std::size_t o = 0; o < rest_length_of_offset_.size(); ++o) {
    rest_length_of_offset_[o] = rest_length[static_cast<std::size_t>(
        lattice::kind_of_offset(lattice::kForwardNeighbours[o]))];
  }
  const lattice::GridShape& shape = lattice.shape;
  if (shape.nodes != decomposition.shape().nodes) {
    throw std::invalid_argument(
        "DistributedElastic: the decomposition is not of the lattice's grid");
  }
  if (!(volume_force_factor > 0.0)) {
    throw std::invalid_argument("DistributedElastic: volume_force_factor must be > 0, got " +
                                std::to_string(volume_force_factor));
  }
  delta_ = forward_offset_deltas(shape);
  backward_order_ = backward_offset_order(delta_);

  // The stiffness of every forward spring of a ghosted node, as a class byte.
  const NodeBox& ghosted = decomposition.ghosted();
  spring_class_.assign(static_cast<std::size_t>(13 * ghosted.node_count()), kNoSpring);
  const lattice::SpringSet& springs = lattice.springs;
  for (std::size_t s = 0; s < springs.size(); ++s) {
    const std::array<int, 3> first = shape.node_coordinates(springs.first[s]);
    if (!ghosted.contains(first[0], first[1], first[2])) continue;
    const std::array<int, 3> second = shape.node_coordinates(springs.second(s));
    const std::array<int, 3> step = {second[0] - first[0], second[1] - first[1],
                                     second[2] - first[2]};
    const auto* const offset =
        std::find(lattice::kForwardNeighbours.begin(), lattice::kForwardNeighbours.end(), step);
    if (offset == lattice::kForwardNeighbours.end()) {
      throw std::invalid_argument("DistributedElastic: spring " + std::to_string(s) +
                                  " does not join forward neighbours");
    }
    const double k = springs.stiffness(s);
    auto known = std::find(stiffness_.begin(), stiffness_.end(), k);
    if (known == stiffness_.end()) {
      if (stiffness_.size() == kNoSpring) {
        throw std::invalid_argument("DistributedElastic: more than 255 distinct spring constants");
      }
      stiffness_.push_back(k);
      known = stiffness_.end() - 1;
    }
    const auto o = offset - lattice::kForwardNeighbours.begin();
    spring_class_[static_cast<std::size_t>(13 * ghosted.offset(first[0], first[1], first[2]) + o)] =
        static_cast<std::uint8_t>(known - stiffness_.begin());
  }
  check_petsc(DMCreateLocalVector(decomposition.dm(), &local_), "DMCreateLocalVector");
}

DistributedElastic::~DistributedElastic() { (void)VecDestroy(&local_); }

ElasticEnergies DistributedElastic::evaluate(Vec positions, Vec gradient) const {
  const LatticeDecomposition& d = decomposition_;
  check_petsc(DMGlobalToLocalBegin(d.dm(), positions, INSERT_VALUES, local_),
              "DMGlobalToLocalBegin");
  check_petsc(DMGlobalToLocalEnd(d.dm(), positions, INSERT_VALUES, local_), "DMGlobalToLocalEnd");
  const PetscScalar* x = nullptr;
  check_petsc(VecGetArrayRead(local_, &x), "VecGetArrayRead");
  const NodeBox cells = cells_touching(d.owned(), d.shape());
  const bool want_gradient = gradient != nullptr;
  const Sums cell_total = evaluate_cells(x, cells, want_gradient);
  PetscScalar* g = nullptr;
  if (want_gradient) check_petsc(VecGetArray(gradient, &g), "VecGetArray");
  const Sums node_total = evaluate_nodes(x, cells, g);
  if (want_gradient) check_petsc(VecRestoreArray(gradient, &g), "VecRestoreArray");
  check_petsc(VecRestoreArrayRead(local_, &x), "VecRestoreArrayRead");

  const Sums local{node_total[0], cell_total[1], node_total[2], cell_total[3]};
  Sums total{};
  sum_in_rank_order(d.comm(), local.data(), total.data(), static_cast<int>(total.size()));
  return {total[0], total[1], total[2], total[3]};
}

DistributedElastic::Sums DistributedElastic::evaluate_cells(const PetscScalar* x,
                                                            const NodeBox& cells,
                                                            bool want_gradient) const {
  const NodeBox& owned = decomposition_.owned();
  const NodeBox& ghosted = decomposition_.ghosted();
  const auto at = [&](int ix, int iy, int iz) { return Map3(x + 3 * ghosted.offset(ix, iy, iz)); };

  // Cells: energy of the owned ones (lower corner owned), gradient coefficients of all that
  // touch an owned node. Lines along z, as the nodes.
  if (want_gradient) cell_terms_.resize(static_cast<std::size_t>(9 * cells.node_count()));
  const std::int64_t cell_lines = std::int64_t{cells.size[0]} * cells.size[1];
  std::vector<Sums> cell_sums(static_cast<std::size_t>(cell_lines), Sums{});
#pragma omp parallel for schedule(static)
  for (std::int64_t line = 0; line < cell_lines; ++line) {
    const int cx = cells.lower[0] + static_cast<int>(line % cells.size[0]);
    const int cy = cells.lower[1] + static_cast<int>(line / cells.size[0]);
    Sums& sums = cell_sums[static_cast<std::size_t>(line)];
    for (int cz = cells.lower[2]; cz < cells.lower[2] + cells.size[2]; ++cz) {
      const bool counted = owned.contains(cx, cy, cz);
      if (!counted && !want_gradient) continue;
      lattice::CellVertices vertices;
      for (int v = 0; v < 8; ++v) {
        const std::array<int, 3> o = lattice::vertex_offset(v);
        vertices[static_cast<std::size_t>(v)] = at(cx + o[0], cy + o[1], cz + o[2]);
      }
      double* t = want_gradient ? cell_terms_.data() + 9 * cells.offset(cx, cy, cz) : nullptr;
      const elastic::CellValue value =
          elastic::cell_value(vertices, kappa_, cell_volume_, volume_factor_, t);
      if (counted) {
        sums[1] += value.energy;
        sums[3] += value.rounding;
      }
    }
  }
  return add_in_order(cell_sums);
}

DistributedElastic::Sums DistributedElastic::evaluate_nodes(const PetscScalar* x,
                                                            const NodeBox& cells,
                                                            PetscScalar* g) const {
  const lattice::GridShape& shape = decomposition_.shape();
  const int nx = shape.nx();
  const int ny = shape.ny();
  const int nz = shape.nz();
  const NodeBox& owned = decomposition_.owned();
  const NodeBox& ghosted = decomposition_.ghosted();
  const bool want_gradient = g != nullptr;

  // Nodes: each owned node's springs in increasing spring index (backward, then forward) and
  // then its cells in increasing cell index, as SpringStencil and CellStencil gather them. The
  // energy of the springs it owns (its forward ones).
  const std::int64_t lines = std::int64_t{owned.size[0]} * owned.size[1];
  std::vector<Sums> node_sums(static_cast<std::size_t>(lines), Sums{});
  // Index steps of the forward offsets in the ghosted box and of a node's cells in the cell
  // box, for the nodes away from the lattice's faces (all their springs and cells exist).
  std::array<std::int64_t, 13> ghosted_step{};
  for (std::size_t o = 0; o < ghosted_step.size(); ++o) {
    const auto& step = lattice::kForwardNeighbours[o];
    ghosted_step[o] = ghosted.offset(ghosted.lower[0] + step[0], ghosted.lower[1] + step[1],
                                     ghosted.lower[2] + step[2]);
  }
  std::array<std::int64_t, 8> cell_step{};
  for (std::size_t k = 0; k < cell_step.size(); ++k) {
    const auto& [dx, dy, dz] = kCellsOfNode[k];
    cell_step[k] = cells.offset(cells.lower[0] + dx, cells.lower[1] + dy, cells.lower[2] + dz);
  }
#pragma omp parallel for schedule(static)
  for (std::int64_t line = 0; line < lines; ++line) {
    const int ix = owned.lower[0] + static_cast<int>(line % owned.size[0]);
    const int iy = owned.lower[1] + static_cast<int>(line / owned.size[0]);
    Sums& sums = node_sums[static_cast<std::size_t>(line)];
    for (int iz = owned.lower[2]; iz < owned.lower[2] + owned.size[2]; ++iz) {
      const bool inside = ix > 0 && ix < nx - 1 && iy > 0 && iy < ny - 1 && iz > 0 && iz < nz - 1;
      const std::int64_t self = ghosted.offset(ix, iy, iz);
      const Map3 xn(x + 3 * self);
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      if (want_gradient) {
        for (const int o : backward_order_) {
          const auto u = static_cast<std::size_t>(o);
          const auto& step = lattice::kForwardNeighbours[u];
          if (!inside && (ix - step[0] < 0 || ix - step[0] >= nx || iy - step[1] < 0 ||
                          iy - step[1] >= ny || iz - step[2] < 0 || iz - step[2] >= nz)) {
            continue;
          }
          const std::int64_t m = self - ghosted_step[u];
          const std::uint8_t k = spring_class_[static_cast<std::size_t>(13 * m + o)];
          const Eigen::Vector3d r = xn - Map3(x + 3 * m);
          const elastic::SpringValue value =
              elastic::spring_value(stiffness_[k], rest_length_of_offset_[u], r.norm());
          sum += Eigen::Vector3d(value.tension * r);
        }
      }
      for (std::size_t o = 0; o < 13; ++o) {
        const std::uint8_t k = spring_class_[static_cast<std::size_t>(13 * self) + o];
        if (k == kNoSpring) continue;
        const Eigen::Vector3d r = Map3(x + 3 * (self + ghosted_step[o])) - xn;
        const elastic::SpringValue value =
            elastic::spring_value(stiffness_[k], rest_length_of_offset_[o], r.norm());
        sum -= Eigen::Vector3d(value.tension * r);
        sums[0] += value.energy;
        sums[2] += value.rounding;
      }
      if (!want_gradient) continue;
      const std::int64_t corner_cell =
          cells.contains(ix, iy, iz) ? cells.offset(ix, iy, iz) : -1;  // the cell at (0, 0, 0)
      for (std::size_t c = 0; c < kCellsOfNode.size(); ++c) {
        const auto& [dx, dy, dz] = kCellsOfNode[c];
        std::int64_t cell = 0;
        if (inside) {
          cell = corner_cell - cell_step[c];
        } else {
          const int cx = ix - dx;
          const int cy = iy - dy;
          const int cz = iz - dz;
          if (cx < 0 || cx >= nx - 1 || cy < 0 || cy >= ny - 1 || cz < 0 || cz >= nz - 1) continue;
          cell = cells.offset(cx, cy, cz);
        }
        sum += elastic::vertex_gradient(cell_terms_.data() + 9 * cell, 2 * dx + 4 * dy + dz);
      }
      Eigen::Map<Eigen::Vector3d>(g + 3 * owned.offset(ix, iy, iz)) = sum;
    }
  }
  return add_in_order(node_sums);
}

}  // namespace mresim::mess
