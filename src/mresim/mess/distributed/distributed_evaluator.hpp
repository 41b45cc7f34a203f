#pragma once

// MessSystem::evaluate with its work split over the processes of a communicator, for a run in
// which every process keeps the whole state (`mpirun -np P mresim run FILE`, docs/mpi.md): every
// process holds the same MessSystem (same positions, M, settings) and calls evaluate() with it
// at the same time; each evaluates the potential on its own box of nodes (DistributedSystem)
// and the gradient is gathered to all of them. The gradient is bitwise MessSystem::evaluate's;
// the energies agree with it to rounding and are bitwise the same on every process, so every
// process's minimiser takes the same decisions.
//
// The positions and the gradient are not distributed (each process holds them whole); the
// evaluation, most of a relaxation's work, is, and so are L-BFGS's stored pairs and its product
// (vector_split(), solvers/lbfgs_memory.hpp). docs/mpi.md has what distributing the
// rest takes.

#include <petscvec.h>  // with MPI's header, without its C++ bindings

#include <Eigen/Core>
#include <memory>

#include "mresim/mess/solvers/block_split.hpp"
#include "mresim/mess/system/system_energy.hpp"

namespace mresim::mess {

class LatticeDecomposition;
class DistributedSystem;

class DistributedEvaluator {
 public:
  // Collective on `comm` at every evaluate().
  explicit DistributedEvaluator(MPI_Comm comm);
  DistributedEvaluator(const DistributedEvaluator&) = delete;
  DistributedEvaluator& operator=(const DistributedEvaluator&) = delete;
  DistributedEvaluator(DistributedEvaluator&&) = delete;
  DistributedEvaluator& operator=(DistributedEvaluator&&) = delete;
  ~DistributedEvaluator();

  // Collective: as system.evaluate(gradient). The split is made for the first system and kept
  // while the same system object (of the same lattice) comes back.
  Evaluation evaluate(MessSystem& system, Eigen::Matrix3Xd* gradient);

  [[nodiscard]] MPI_Comm comm() const { return comm_; }

  // How the minimiser's free-coordinate vectors are shared among these processes
  // (distributed/mpi_block_split.hpp); the same object on every call.
  [[nodiscard]] std::shared_ptr<const detail::BlockSplit> vector_split() const { return split_; }

 private:
  void bind(MessSystem& system);

  MPI_Comm comm_;
  std::shared_ptr<const detail::BlockSplit> split_;
  const MessSystem* bound_ = nullptr;
  std::int64_t bound_nodes_ = 0;
  std::unique_ptr<LatticeDecomposition> decomposition_;
  std::unique_ptr<DistributedSystem> system_;
  Vec positions_ = nullptr;
  Vec gradient_ = nullptr;
};

}  // namespace mresim::mess
