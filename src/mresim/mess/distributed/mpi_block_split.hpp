#pragma once

// BlockSplit (solvers/block_split.hpp) over the processes of an MPI communicator: the
// kSumBlock-entry blocks of a vector are dealt out in contiguous runs, process r taking blocks
// [B r / P, B (r + 1) / P) of B, and shared with MPI_Allgatherv. Every call is collective.

#include <petscsys.h>  // MPI, without its C++ bindings

#include "mresim/mess/solvers/block_split.hpp"

namespace mresim::mess {

class MpiBlockSplit final : public detail::BlockSplit {
 public:
  explicit MpiBlockSplit(MPI_Comm comm);

  [[nodiscard]] detail::OwnedBlocks owned(Eigen::Index n) const override;
  void share_block_sums(std::vector<double>& block_sums, Eigen::Index n) const override;
  void share_entries(Eigen::VectorXd& v) const override;
  [[nodiscard]] int rank() const override { return rank_; }
  [[nodiscard]] int processes() const override { return size_; }
  void share_from(int owner, std::vector<double>& values) const override;

 private:
  [[nodiscard]] detail::OwnedBlocks owned_by(int rank, Eigen::Index n) const;

  MPI_Comm comm_;
  int rank_ = 0;
  int size_ = 1;
};

}  // namespace mresim::mess
