#include "mresim/mess/distributed/distributed_evaluator.hpp"

#include "mresim/mess/distributed/distributed_system.hpp"
#include "mresim/mess/distributed/lattice_decomposition.hpp"
#include "mresim/mess/distributed/mpi_block_split.hpp"
#include "mresim/mess/solvers/amg_preconditioner.hpp"

namespace mresim::mess {

DistributedEvaluator::DistributedEvaluator(MPI_Comm comm) : comm_(comm) {
  initialise_petsc();
  split_ = std::make_shared<MpiBlockSplit>(comm_);
}

DistributedEvaluator::~DistributedEvaluator() {
  (void)VecDestroy(&positions_);
  (void)VecDestroy(&gradient_);
}

void DistributedEvaluator::bind(MessSystem& system) {
  if (bound_ == &system && bound_nodes_ == system.node_count()) return;
  system_.reset();
  (void)VecDestroy(&positions_);
  (void)VecDestroy(&gradient_);
  decomposition_ = std::make_unique<LatticeDecomposition>(system.lattice().shape, comm_);
  system_ = std::make_unique<DistributedSystem>(system, *decomposition_);
  positions_ = decomposition_->create_global_vector();
  gradient_ = decomposition_->create_global_vector();
  bound_ = &system;
  bound_nodes_ = system.node_count();
}

Evaluation DistributedEvaluator::evaluate(MessSystem& system, Eigen::Matrix3Xd* gradient) {
  bind(system);
  decomposition_->scatter(system.positions(), positions_);
  Evaluation e = system_->evaluate(positions_, gradient != nullptr ? gradient_ : nullptr);
  if (gradient != nullptr) *gradient = decomposition_->gather(gradient_);
  return e;
}

}  // namespace mresim::mess
