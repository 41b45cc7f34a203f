#pragma once

// How the fixed blocks of a free-coordinate vector (kSumBlock entries each, fixed_order.hpp) are
// shared among the processes of a distributed relaxation (docs/mpi.md), so that a solver can
// keep only its own process's blocks of the vectors it stores and still form dot products that
// are bitwise those of a single process: each process sums its own blocks, every block's sum is
// sent to every process, and each adds them all in block order, as vector_algebra.hpp does on
// one process. The split itself (which blocks, how they travel) lives with the MPI code
// (distributed/mpi_block_split.hpp); the solvers see only this interface.

#include <Eigen/Core>
#include <vector>

#include "mresim/mess/system/fixed_order.hpp"

namespace mresim::mess::detail {

// The blocks [first_block, last_block) of a vector of n entries, i.e. its entries [begin, end).
struct OwnedBlocks {
  Eigen::Index first_block = 0;
  Eigen::Index last_block = 0;
  Eigen::Index begin = 0;
  Eigen::Index end = 0;
  [[nodiscard]] Eigen::Index length() const { return end - begin; }
};

// The whole vector on one process: every block.
inline OwnedBlocks all_blocks(Eigen::Index n) { return {0, (n + kSumBlock - 1) / kSumBlock, 0, n}; }

class BlockSplit {
 public:
  BlockSplit() = default;
  BlockSplit(const BlockSplit&) = delete;
  BlockSplit& operator=(const BlockSplit&) = delete;
  BlockSplit(BlockSplit&&) = delete;
  BlockSplit& operator=(BlockSplit&&) = delete;
  virtual ~BlockSplit() = default;

  // This process's blocks of a vector of n entries (contiguous; possibly none).
  [[nodiscard]] virtual OwnedBlocks owned(Eigen::Index n) const = 0;

  // Collective. `block_sums` has one entry per block of a vector of n entries, this process's
  // blocks filled in; on return every process's blocks are filled in, on every process.
  virtual void share_block_sums(std::vector<double>& block_sums, Eigen::Index n) const = 0;

  // Collective. `v` is a whole vector with this process's entries set; on return every entry
  // is set, on every process, to the value its owner had.
  virtual void share_entries(Eigen::VectorXd& v) const = 0;

  // Work split by whole items rather than blocks (the multilevel correction's levels, each
  // built by one process): this process's rank among the split's processes, and their number.
  [[nodiscard]] virtual int rank() const = 0;
  [[nodiscard]] virtual int processes() const = 0;
  // Collective. On return every process's `values` are those of process `owner` (its length
  // too).
  virtual void share_from(int owner, std::vector<double>& values) const = 0;
};

}  // namespace mresim::mess::detail
