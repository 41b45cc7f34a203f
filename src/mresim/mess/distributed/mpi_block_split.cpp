#include "mresim/mess/distributed/mpi_block_split.hpp"

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "mresim/mess/solvers/amg_preconditioner.hpp"
#include "mresim/mess/system/fixed_order.hpp"

namespace mresim::mess {

namespace {

// MPI counts are int: a vector of more than 2^31 entries (700 M nodes) cannot be shared.
int as_count(Eigen::Index n) {
  if (n > std::numeric_limits<int>::max()) {
    throw std::length_error("MpiBlockSplit: a vector of more than 2^31 entries");
  }
  return static_cast<int>(n);
}

}  // namespace

MpiBlockSplit::MpiBlockSplit(MPI_Comm comm) : comm_(comm) {
  initialise_petsc();  // starts MPI if this process has not yet
  MPI_Comm_rank(comm_, &rank_);
  MPI_Comm_size(comm_, &size_);
}

detail::OwnedBlocks MpiBlockSplit::owned_by(int rank, Eigen::Index n) const {
  const Eigen::Index blocks = (n + detail::kSumBlock - 1) / detail::kSumBlock;
  const Eigen::Index first = blocks * rank / size_;
  const Eigen::Index last = blocks * (rank + 1) / size_;
  return {first, last, std::min(n, first * detail::kSumBlock),
          std::min(n, last * detail::kSumBlock)};
}

detail::OwnedBlocks MpiBlockSplit::owned(Eigen::Index n) const { return owned_by(rank_, n); }

void MpiBlockSplit::share_block_sums(std::vector<double>& block_sums, Eigen::Index n) const {
  std::vector<int> counts(static_cast<std::size_t>(size_));
  std::vector<int> starts(static_cast<std::size_t>(size_));
  for (int r = 0; r < size_; ++r) {
    const detail::OwnedBlocks o = owned_by(r, n);
    counts[static_cast<std::size_t>(r)] = as_count(o.last_block - o.first_block);
    starts[static_cast<std::size_t>(r)] = as_count(o.first_block);
  }
  MPI_Allgatherv(MPI_IN_PLACE, 0, MPI_DATATYPE_NULL, block_sums.data(), counts.data(),
                 starts.data(), MPI_DOUBLE, comm_);
}

void MpiBlockSplit::share_entries(Eigen::VectorXd& v) const {
  std::vector<int> counts(static_cast<std::size_t>(size_));
  std::vector<int> starts(static_cast<std::size_t>(size_));
  for (int r = 0; r < size_; ++r) {
    const detail::OwnedBlocks o = owned_by(r, v.size());
    counts[static_cast<std::size_t>(r)] = as_count(o.length());
    starts[static_cast<std::size_t>(r)] = as_count(o.begin);
  }
  MPI_Allgatherv(MPI_IN_PLACE, 0, MPI_DATATYPE_NULL, v.data(), counts.data(), starts.data(),
                 MPI_DOUBLE, comm_);
}

void MpiBlockSplit::share_from(int owner, std::vector<double>& values) const {
  if (owner < 0 || owner >= size_) {
    throw std::invalid_argument("MpiBlockSplit::share_from: owner " + std::to_string(owner) +
                                " is not a rank of " + std::to_string(size_) + " processes");
  }
  long long length = rank_ == owner ? static_cast<long long>(values.size()) : 0;
  MPI_Bcast(&length, 1, MPI_LONG_LONG, owner, comm_);
  values.resize(static_cast<std::size_t>(length));
  MPI_Bcast(values.data(), as_count(static_cast<Eigen::Index>(length)), MPI_DOUBLE, owner, comm_);
}

}  // namespace mresim::mess
