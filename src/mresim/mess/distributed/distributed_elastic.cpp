#include "mresim/mess/distributed/distributed_elastic.hpp"

#include <omp.h>
#include <petscdmda.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "mresim/mess/terms/cell_rows.hpp"
#include "mresim/mess/terms/elastic_formulas.hpp"
#include "mresim/mess/terms/grid_stencil.hpp"
#include "mresim/mess/terms/spring_rows.hpp"

namespace mresim::mess {

namespace {

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
  backward_order_ = backward_offset_order(forward_offset_deltas(shape));

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
    spring_class_[static_cast<std::size_t>(o * ghosted.node_count() +
                                           ghosted.offset(first[0], first[1], first[2]))] =
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
  load_components(x);
  const Sums cell_total = evaluate_cells(cells, want_gradient);
  PetscScalar* g = nullptr;
  if (want_gradient) check_petsc(VecGetArray(gradient, &g), "VecGetArray");
  const Sums node_total = evaluate_nodes(cells, g);
  if (want_gradient) check_petsc(VecRestoreArray(gradient, &g), "VecRestoreArray");
  check_petsc(VecRestoreArrayRead(local_, &x), "VecRestoreArrayRead");

  const Sums local{node_total[0], cell_total[1], node_total[2], cell_total[3]};
  Sums total{};
  sum_in_rank_order(d.comm(), local.data(), total.data(), static_cast<int>(total.size()));
  return {total[0], total[1], total[2], total[3]};
}

DistributedElastic::Sums DistributedElastic::evaluate_cells(const NodeBox& cells,
                                                            bool want_gradient) const {
  const NodeBox& owned = decomposition_.owned();
  // Cells: energy of the owned ones (lower corner owned), gradient coefficients of all that
  // touch an owned node. One z-line of cells at a time, one SIMD lane per cell
  // (terms/cell_rows.hpp): the same operations per cell as elastic::cell_value, so the
  // coefficients and energies are bitwise its.
  const std::int64_t cell_lines = std::int64_t{cells.size[0]} * cells.size[1];
  const std::int64_t height = cells.size[2];
  cell_terms_.resize(static_cast<std::size_t>(9 * cells.node_count()));
  cell_scratch_.resize(static_cast<std::size_t>(std::int64_t{omp_get_max_threads()} * 2 * height));
  std::vector<Sums> cell_sums(static_cast<std::size_t>(cell_lines), Sums{});
#pragma omp parallel
  {
    double* const energy = cell_scratch_.data() + std::int64_t{omp_get_thread_num()} * 2 * height;
    double* const rounding = energy + height;
#pragma omp for schedule(static)
    for (std::int64_t line = 0; line < cell_lines; ++line) {
      const int cx = cells.lower[0] + static_cast<int>(line % cells.size[0]);
      const int cy = cells.lower[1] + static_cast<int>(line / cells.size[0]);
      const bool owned_line = owned.contains(cx, cy, owned.lower[2]);
      if ((!owned_line && !want_gradient) || height == 0) continue;
      cell_rows::Corners corners{};
      for (std::size_t v = 0; v < 8; ++v) {
        const std::array<int, 3> o = lattice::vertex_offset(static_cast<int>(v));
        const spring_rows::Components c = components(
            decomposition_.ghosted().offset(cx + o[0], cy + o[1], cells.lower[2] + o[2]));
        corners.x[v] = c.x;
        corners.y[v] = c.y;
        corners.z[v] = c.z;
      }
      cell_rows::coefficients(height, corners, kappa_, cell_volume_, volume_factor_,
                              line_terms(line, height), energy, rounding);
      if (!owned_line) continue;
      Sums& sums = cell_sums[static_cast<std::size_t>(line)];
      const int z_begin = std::max(cells.lower[2], owned.lower[2]);
      const int z_end = std::min(cells.lower[2] + cells.size[2], owned.lower[2] + owned.size[2]);
      for (int cz = z_begin; cz < z_end; ++cz) {
        sums[1] += energy[cz - cells.lower[2]];
        sums[3] += rounding[cz - cells.lower[2]];
      }
    }
  }
  return add_in_order(cell_sums);
}

cell_rows::Coefficients<double*> DistributedElastic::line_terms(std::int64_t line,
                                                                std::int64_t height) const {
  cell_rows::Coefficients<double*> t{};
  double* const first = cell_terms_.data() + 9 * line * height;
  for (std::size_t k = 0; k < 9; ++k) t[k] = first + static_cast<std::int64_t>(k) * height;
  return t;
}

spring_rows::Components DistributedElastic::components(std::int64_t node) const {
  const std::int64_t nodes = decomposition_.ghosted().node_count();
  const double* const c = components_.data();
  return {c + node, c + nodes + node, c + 2 * nodes + node};
}

double* DistributedElastic::tensions_at(int ix, int iy, std::int64_t offset, int iz) const {
  const NodeBox& ghosted = decomposition_.ghosted();
  const std::int64_t line = std::int64_t{iy % 2} * ghosted.size[0] + (ix - ghosted.lower[0]);
  return tensions_.data() + (line * 13 + offset) * ghosted.size[2] + (iz - ghosted.lower[2]);
}

void DistributedElastic::line_tensions(int ix, int iy, double* energy, double* rounding,
                                       Sums& sums) const {
  const NodeBox& owned = decomposition_.owned();
  const NodeBox& ghosted = decomposition_.ghosted();
  const std::int64_t nodes = ghosted.node_count();
  const int z_begin = ghosted.lower[2];
  const int z_end = ghosted.lower[2] + ghosted.size[2];
  const int owned_z_begin = owned.lower[2];
  const int owned_z_end = owned.lower[2] + owned.size[2];
  const bool owned_line = owned.contains(ix, iy, owned_z_begin);
  for (std::size_t o = 0; o < 13; ++o) {
    const auto& [dx, dy, dz] = lattice::kForwardNeighbours[o];
    // Both ends in the ghosted box.
    if (!ghosted.contains(ix + dx, iy + dy, z_begin)) continue;
    const int lo = std::max(z_begin, z_begin - dz);
    const int hi = std::min(z_end, z_end - dz);
    if (lo >= hi) continue;
    const std::int64_t first = ghosted.offset(ix, iy, lo);
    spring_rows::tensions(hi - lo, components(first),
                          components(ghosted.offset(ix + dx, iy + dy, lo + dz)),
                          spring_class_.data() + static_cast<std::int64_t>(o) * nodes + first,
                          stiffness_.data(), rest_length_of_offset_[o],
                          tensions_at(ix, iy, static_cast<std::int64_t>(o), lo), energy, rounding);
    if (!owned_line) continue;
    for (int iz = std::max(lo, owned_z_begin); iz < std::min(hi, owned_z_end); ++iz) {
      sums[0] += energy[iz - lo];
      sums[2] += rounding[iz - lo];
    }
  }
}

void DistributedElastic::line_spring_gradient(int ix, int iy, double* gx, double* gy,
                                              double* gz) const {
  const lattice::GridShape& shape = decomposition_.shape();
  const NodeBox& owned = decomposition_.owned();
  const NodeBox& ghosted = decomposition_.ghosted();
  const int owned_z_begin = owned.lower[2];
  const int owned_z_end = owned.lower[2] + owned.size[2];
  const auto in_lattice = [&](int jx, int jy) {
    return jx >= 0 && jx < shape.nx() && jy >= 0 && jy < shape.ny();
  };
  std::fill(gx, gx + owned.size[2], 0.0);
  std::fill(gy, gy + owned.size[2], 0.0);
  std::fill(gz, gz + owned.size[2], 0.0);
  for (const int o : backward_order_) {
    const auto& [dx, dy, dz] = lattice::kForwardNeighbours[static_cast<std::size_t>(o)];
    if (!in_lattice(ix - dx, iy - dy)) continue;
    const int lo = std::max(owned_z_begin, dz);
    const int hi = std::min(owned_z_end, shape.nz() + dz);
    if (lo >= hi) continue;
    const std::int64_t k = lo - owned_z_begin;
    spring_rows::add_backward(hi - lo, tensions_at(ix - dx, iy - dy, o, lo - dz),
                              components(ghosted.offset(ix - dx, iy - dy, lo - dz)),
                              components(ghosted.offset(ix, iy, lo)), gx + k, gy + k, gz + k);
  }
  for (std::size_t o = 0; o < 13; ++o) {
    const auto& [dx, dy, dz] = lattice::kForwardNeighbours[o];
    if (!in_lattice(ix + dx, iy + dy)) continue;
    const int lo = std::max(owned_z_begin, -dz);
    const int hi = std::min(owned_z_end, shape.nz() - dz);
    if (lo >= hi) continue;
    const std::int64_t k = lo - owned_z_begin;
    spring_rows::subtract_forward(hi - lo, tensions_at(ix, iy, static_cast<std::int64_t>(o), lo),
                                  components(ghosted.offset(ix, iy, lo)),
                                  components(ghosted.offset(ix + dx, iy + dy, lo + dz)), gx + k,
                                  gy + k, gz + k);
  }
}

void DistributedElastic::line_gradient(int ix, int iy, const NodeBox& cells, double* gx, double* gy,
                                       double* gz, PetscScalar* g) const {
  const lattice::GridShape& shape = decomposition_.shape();
  const NodeBox& owned = decomposition_.owned();
  const int owned_z_begin = owned.lower[2];
  const int owned_z_end = owned.lower[2] + owned.size[2];
  line_spring_gradient(ix, iy, gx, gy, gz);
  // Then each node's cells in CellStencil's order, one offset at a time along the line: the
  // node is local vertex 2 dx + 4 dy + dz of cell (ix - dx, iy - dy, iz - dz), signs by dx, dy,
  // dz (elastic::vertex_gradient).
  for (const auto& [dx, dy, dz] : kCellsOfNode) {
    const int cx = ix - dx;
    const int cy = iy - dy;
    if (cx < 0 || cx >= shape.nx() - 1 || cy < 0 || cy >= shape.ny() - 1) continue;
    const int lo = std::max(owned_z_begin, dz);                 // cz = iz - dz >= 0
    const int hi = std::min(owned_z_end, shape.nz() - 1 + dz);  // cz < nz - 1
    if (lo >= hi) continue;
    const std::int64_t line =
        (cx - cells.lower[0]) + std::int64_t{cells.size[0]} * (cy - cells.lower[1]);
    const cell_rows::Coefficients<double*> terms = line_terms(line, cells.size[2]);
    cell_rows::Coefficients<const double*> t{};
    for (std::size_t k = 0; k < 9; ++k) t[k] = terms[k] + (lo - dz - cells.lower[2]);
    const std::int64_t k = lo - owned_z_begin;
    cell_rows::add_vertex_gradient(hi - lo, t, dx == 1 ? 1.0 : -1.0, dy == 1 ? 1.0 : -1.0,
                                   dz == 1 ? 1.0 : -1.0, gx + k, gy + k, gz + k);
  }
  for (int iz = owned_z_begin; iz < owned_z_end; ++iz) {
    const std::int64_t k = iz - owned_z_begin;
    PetscScalar* const node = g + 3 * owned.offset(ix, iy, iz);
    node[0] = gx[k];
    node[1] = gy[k];
    node[2] = gz[k];
  }
}

void DistributedElastic::load_components(const PetscScalar* x) const {
  const std::int64_t nodes = decomposition_.ghosted().node_count();
  components_.resize(static_cast<std::size_t>(3 * nodes));
  double* const c = components_.data();
#pragma omp parallel for schedule(static)
  for (std::int64_t n = 0; n < nodes; ++n) {
    c[n] = x[3 * n];
    c[nodes + n] = x[3 * n + 1];
    c[2 * nodes + n] = x[3 * n + 2];
  }
}

DistributedElastic::Sums DistributedElastic::evaluate_nodes(const NodeBox& cells,
                                                            PetscScalar* g) const {
  const NodeBox& owned = decomposition_.owned();
  const NodeBox& ghosted = decomposition_.ghosted();
  const std::int64_t row_lines = ghosted.size[0];
  tensions_.resize(static_cast<std::size_t>(2 * row_lines * 13 * ghosted.size[2]));
  std::vector<Sums> line_sums(static_cast<std::size_t>(row_lines * ghosted.size[1]), Sums{});
  // Per thread: a line's energies and roundings, and an owned line's gradient.
  const std::int64_t scratch_per_thread =
      2 * std::int64_t{ghosted.size[2]} + 3 * std::int64_t{owned.size[2]};
  row_scratch_.resize(static_cast<std::size_t>(omp_get_max_threads() * scratch_per_thread));

#pragma omp parallel
  {
    double* const energy = row_scratch_.data() + omp_get_thread_num() * scratch_per_thread;
    double* const rounding = energy + ghosted.size[2];
    double* const gx = rounding + ghosted.size[2];
    double* const gy = gx + owned.size[2];
    double* const gz = gy + owned.size[2];
    for (int iy = ghosted.lower[1]; iy < ghosted.lower[1] + ghosted.size[1]; ++iy) {
#pragma omp for schedule(static)
      for (std::int64_t l = 0; l < row_lines; ++l) {
        line_tensions(ghosted.lower[0] + static_cast<int>(l), iy, energy, rounding,
                      line_sums[static_cast<std::size_t>((iy - ghosted.lower[1]) * row_lines + l)]);
      }
      if (g == nullptr || iy < owned.lower[1] || iy >= owned.lower[1] + owned.size[1]) continue;
#pragma omp for schedule(static)
      for (std::int64_t l = 0; l < owned.size[0]; ++l) {
        line_gradient(owned.lower[0] + static_cast<int>(l), iy, cells, gx, gy, gz, g);
      }
    }
  }
  return add_in_order(line_sums);
}

}  // namespace mresim::mess
