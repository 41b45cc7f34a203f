#pragma once

// The elastic Hessian of the 3D lattice (springs eq. 4.62 and volume eq. 4.64, times their
// force factors) as a sparse matrix over all 3N node coordinates (row and column 3 n + a), in
// the compressed-row layout of PETSc's AIJ format, for the Newton solver's preconditioner
// (amg_preconditioner.hpp).
//
// Memory. The pattern is built once from the lattice's cells and springs: row block n holds
// the nodes that share a cell or a spring with n (27 inside the lattice), so a row has up to
// 81 entries: 81 x (8 + 4) bytes per row, 2.9 kB per node. The values are assembled straight
// from the terms' 3 x 3 node blocks (terms/hessian_blocks.hpp); no triplet list (36 entries
// per spring and 576 per cell, about 9 kB per node) is ever built.
//
// Constraints. Coordinates that are not free on their own (held ones, and the nodes of rigid
// groups, whose translation is one variable of the whole group) get an identity row and
// column times the mean diagonal of the free coordinates. The matrix stays symmetric positive
// (semi)definite and keeps its 3 x 3 block structure, which the multigrid's rigid-body
// near-null space needs.

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "mresim/mess/lattice/lattice.hpp"

namespace mresim::mess {

class MessSystem;

class ElasticMatrix {
 public:
  // The pattern of `lattice` (its cells and springs).
  explicit ElasticMatrix(const lattice::Lattice& lattice);

  // Values of the system's elastic Hessian at its current positions, times `scale`; rows and
  // columns of the coordinates with free[3 n + a] == 0 become scaled identity (see above).
  void assemble(const MessSystem& system, const std::vector<std::uint8_t>& free, double scale);

  std::int32_t rows() const { return static_cast<std::int32_t>(row_start_.size()) - 1; }
  const std::vector<std::int32_t>& row_start() const { return row_start_; }
  const std::vector<std::int32_t>& columns() const { return columns_; }
  const std::vector<double>& values() const { return values_; }
  std::vector<double>& mutable_values() { return values_; }

  // y = A x (3N each), for tests.
  Eigen::VectorXd multiply(const Eigen::VectorXd& x) const;

  // Where block (i, j) starts in row 3 i: the index of the value for column 3 j; -1 if the
  // pattern has no such block.
  std::int64_t block_offset(std::int64_t i, std::int64_t j) const;
  // Entries per row of node i's rows (3 x its neighbour count).
  std::int64_t row_length(std::int64_t i) const {
    return 3 * (neighbour_start_[static_cast<std::size_t>(i) + 1] -
                neighbour_start_[static_cast<std::size_t>(i)]);
  }

 private:
  void impose_identity(const std::vector<std::uint8_t>& free);

  std::vector<std::int64_t> neighbour_start_;  // node -> its neighbours (sorted), CSR
  std::vector<std::int32_t> neighbours_;
  std::vector<std::int32_t> row_start_;  // 3N + 1
  std::vector<std::int32_t> columns_;
  std::vector<double> values_;
};

}  // namespace mresim::mess
