#pragma once

// The elastic terms of the 3D model (springs, eq. 4.62, and volume, eq. 4.64 x V0) evaluated
// over a LatticeDecomposition: each process computes the energy of the springs and cells it
// owns and the gradient at its own nodes, from its nodes' and the ghost layer's positions
// (PETSc's DMGlobalToLocal brings in the ghosts). The energies are summed over the processes
// in rank order (sum_in_rank_order: the same totals on every process).
//
// Same numbers as one process. Every node gathers its springs and cells in the order of the
// single-process kernels (terms/grid_stencil.hpp: increasing spring and cell index) with the
// same per-spring and per-cell formulas, so the gradient is bitwise ElasticTerms::evaluate's on
// any number of processes and threads. The springs run as the single-process spring kernel
// runs them, in SIMD rows along z (terms/spring_rows.hpp): each row of z-lines (one y) first
// computes the tensions of its springs once, offset by offset, then the gradient of its owned
// nodes from its own tensions (forward springs) and the previous row's (backward springs, which
// start at most one y below), so only two rows' tensions are kept. The cells run in SIMD rows
// too (terms/cell_rows.hpp), along z-lines of cells from the same component arrays: each line's
// gradient coefficients first, then each owned z-line adds its cells' parts after its springs',
// in the single-process order. The energies are summed in another order (per grid line,
// then over processes), so they agree with the single-process sums to rounding (relative 1e-15
// or so), not bitwise.
//
// Memory per process: one byte per forward spring of its ghosted nodes (the spring's stiffness
// as an index into a table of the lattice's distinct spring constants), 72 bytes per cell
// touching its nodes (gradient coefficients), the ghosted positions as three component arrays
// (24 bytes per node), a cell line's energies per thread, two rows' tensions (13 doubles per node
// of two of its y-rows), and PETSc's ghosted position vector. The set-up reads the whole lattice,
// which every process builds today (docs/mpi.md: what is distributed so far and what is next).

#include <petscvec.h>

#include <array>
#include <cstdint>
#include <vector>

#include "mresim/mess/distributed/lattice_decomposition.hpp"
#include "mresim/mess/lattice/lattice.hpp"
#include "mresim/mess/terms/cell_rows.hpp"
#include "mresim/mess/terms/elastic_terms.hpp"
#include "mresim/mess/terms/spring_rows.hpp"

namespace mresim::mess {

class DistributedElastic {
 public:
  // `decomposition` must outlive this object and be of `lattice`'s grid; `lattice.springs`
  // must be the forward-neighbour set of build_springs (as for SpringStencil). Collective.
  DistributedElastic(const lattice::Lattice& lattice, const LatticeDecomposition& decomposition,
                     double volume_force_factor);
  DistributedElastic(const DistributedElastic&) = delete;
  DistributedElastic& operator=(const DistributedElastic&) = delete;
  DistributedElastic(DistributedElastic&&) = delete;
  DistributedElastic& operator=(DistributedElastic&&) = delete;
  ~DistributedElastic();

  // Collective. `positions`: a global vector of the decomposition (m). If `gradient` is not
  // null, it (a global vector too) is overwritten with d(springs)/dx + volume_force_factor
  // d(volume)/dx at the owned nodes (J/m). The energies are the totals over all processes.
  ElasticEnergies evaluate(Vec positions, Vec gradient) const;

  [[nodiscard]] double volume_force_factor() const { return volume_factor_; }

 private:
  static constexpr std::uint8_t kNoSpring = 255;
  // Springs, volume and their rounding scales (ElasticEnergies' order) of one process.
  using Sums = std::array<double, 4>;

  // Copies the ghosted positions x (3 per node) into the three component arrays that the row
  // formulas read (components_).
  void load_components(const PetscScalar* x) const;
  // The cells touching the owned nodes (`cells`), z-line by z-line: the energy of the owned
  // ones (lower corner owned) and every line's gradient coefficients that the gradient needs
  // (all of them if want_gradient, else only the owned lines').
  Sums evaluate_cells(const NodeBox& cells, bool want_gradient) const;
  // The nine coefficient arrays of cell z-line `line` (cx - lower + size_x (cy - lower) in
  // `cells`), each of the cells box's height, in cell_terms_.
  [[nodiscard]] cell_rows::Coefficients<double*> line_terms(std::int64_t line,
                                                            std::int64_t height) const;
  // The owned nodes: the energy of their forward springs and, if g is not null, the gradient
  // (springs, then cells) at each; row by row (one y), each row's lines in parallel.
  Sums evaluate_nodes(const NodeBox& cells, PetscScalar* g) const;
  // The ghosted z-line (ix, iy): the tensions of its forward springs with both ends in the
  // ghosted box (tensions_at), and, on an owned line, the owned springs' energies and rounding
  // scales added to sums[0] and sums[2]. energy, rounding: scratch of the ghosted box's height.
  void line_tensions(int ix, int iy, double* energy, double* rounding, Sums& sums) const;
  // The owned z-line (ix, iy): g at its nodes, springs (gx, gy, gz: scratch of the owned
  // height) then cells; its row's and the row below's tensions must be computed.
  void line_gradient(int ix, int iy, const NodeBox& cells, double* gx, double* gy, double* gz,
                     PetscScalar* g) const;
  // gx, gy, gz = the springs' part of the gradient of the owned z-line (ix, iy), each node's
  // springs in increasing spring index (backward, then forward), as SpringStencil gathers them.
  void line_spring_gradient(int ix, int iy, double* gx, double* gy, double* gz) const;
  // The ghosted node's component arrays, and a spring tension's slot (two rows of y kept).
  [[nodiscard]] spring_rows::Components components(std::int64_t node) const;
  [[nodiscard]] double* tensions_at(int ix, int iy, std::int64_t offset, int iz) const;

  const LatticeDecomposition& decomposition_;
  double kappa_ = 0.0;                              // J/m^3
  double cell_volume_ = 0.0;                        // V0 = l_e^3
  double volume_factor_ = 1.0;                      // volume_force_factor
  std::array<double, 13> rest_length_of_offset_{};  // by forward offset
  std::array<int, 13> backward_order_{};            // offsets by decreasing delta
  std::vector<double> stiffness_;                   // the distinct spring constants (N/m)
  // Per forward offset o and ghosted node n (NodeBox::offset of the ghosted box), at
  // o x (ghosted nodes) + n: index into stiffness_, or kNoSpring where the neighbour is outside
  // the lattice.
  std::vector<std::uint8_t> spring_class_;
  Vec local_ = nullptr;  // positions of the ghosted box
  // 9 per cell touching an owned node: per z-line of cells, nine arrays along z (line_terms).
  mutable std::vector<double> cell_terms_;
  // One evaluation's scratch: the ghosted positions as x, y and z arrays; the forward springs'
  // tensions of two rows of z-lines (tensions_at); per thread a line's energies and an owned
  // line's gradient.
  mutable std::vector<double> components_;
  mutable std::vector<double> tensions_;
  mutable std::vector<double> row_scratch_;
  mutable std::vector<double> cell_scratch_;  // per thread a cell line's energies and roundings
};

}  // namespace mresim::mess
