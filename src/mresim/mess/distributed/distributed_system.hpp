#pragma once

// The 3D system's whole potential and its gradient (MessSystem::evaluate) over a
// LatticeDecomposition: the positions and the gradient are global vectors of the decomposition,
// each process holding its own nodes. Step 1 of docs/mpi.md's "What comes next".
//
//  - springs and volume: DistributedElastic (each process its own nodes, ghost layer);
//  - the particle centres: every particle node's position is gathered to every process
//    (MPI_Allgatherv; a few thousand nodes at most), which computes the centres as
//    MessSystem::particle_centres does, in the same order, so they are bitwise the same;
//  - the magnetization: solved on every process by the MessSystem's own update rule
//    (MessSystem::update_magnetization_at) at those centres: the same M everywhere;
//  - Zeeman, dipole, self-energy and WCA: functions of the centres and M only, evaluated on
//    every process; each particle's centre gradient is shared over its nodes as in
//    MessSystem::evaluate, each process adding the shares of its own nodes;
//  - load: -sum f.(x - x0) over each process's nodes, summed over the processes.
// The gradient at every node is bitwise MessSystem::evaluate's (same operations in the same
// order at every node); the energies of the node sums (springs, volume, load) agree to
// rounding. Optional terms ([terms.<name>]) are not supported yet: the constructor refuses them.
//
// The MessSystem holds the model, the settings, the applied forces and M (with its solve
// statistics, which these evaluations update); its own positions are not used.

#include <petscvec.h>

#include <cstdint>
#include <string_view>
#include <vector>

#include "mresim/mess/distributed/distributed_elastic.hpp"
#include "mresim/mess/distributed/lattice_decomposition.hpp"
#include "mresim/mess/system/system_energy.hpp"

namespace mresim::mess {

class DistributedSystem {
 public:
  // `system` and `decomposition` must outlive this object; the decomposition must be of the
  // system's lattice. Collective. Throws std::invalid_argument for a term it cannot evaluate.
  DistributedSystem(MessSystem& system, const LatticeDecomposition& decomposition);

  // Collective: MessSystem::evaluate at `positions` (a global vector, m). M is re-solved per
  // the system's update rule; if `gradient` is not null it is overwritten with the gradient
  // of the potential at the owned nodes (J/m; held coordinates not zeroed).
  Evaluation evaluate(Vec positions, Vec gradient);

  // Whether a term of this name can be evaluated here: the elastic terms and the load over the
  // processes' nodes, and the terms that read only the particle centres and magnetizations
  // (the magnetic ones, WCA, the optional field_gradient) on every process. A new term must be
  // added to the list once its distributed form is decided (a term that reads node positions
  // needs its own sum over the owned nodes, as the load has).
  [[nodiscard]] static bool supports(std::string_view term);

  // The particle centres at the last evaluate() (3 x N_p, m), the same on every process.
  const Eigen::Matrix3Xd& centres() const { return centres_; }

 private:
  // Every particle node's position, in the order of lattice.particle_nodes (concatenated).
  Eigen::Matrix3Xd gather_particle_nodes(const PetscScalar* owned_positions) const;

  MessSystem& system_;
  const LatticeDecomposition& decomposition_;
  DistributedElastic elastic_;
  // Position in the concatenated particle-node list of each owned particle node, and its
  // offset in the owned box; the counts and displacements of every process's share.
  std::vector<std::int64_t> owned_particle_slots_;
  std::vector<std::int64_t> owned_particle_offsets_;
  std::vector<std::int32_t> owned_particle_of_;  // the particle of each
  std::vector<int> particle_counts_;             // doubles per process (3 per node)
  std::vector<int> particle_displacements_;      // doubles
  std::vector<std::int64_t> gathered_slots_;     // slots in the order the processes send them
  std::int64_t particle_node_total_ = 0;
  Eigen::Matrix3Xd centres_;
};

}  // namespace mresim::mess
