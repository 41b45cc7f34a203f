#pragma once

// A preconditioner for the minimisers: an approximate inverse of the lattice's Hessian in the
// free variables, used as the initial inverse Hessian of L-BFGS (H0 = gamma P).
//
// Why. Particle springs are 1e4 times stiffer than the polymer's (Section 4.2.2), so the
// Hessian's eigenvalues span the particles' internal modes (~1e4 k) down to the polymer's
// long-wave modes, and an unpreconditioned L-BFGS needs ~20 times more iterations with
// particles than without (measured on small blocks). A plain diagonal (Jacobi) scaling fixes
// the internal modes but makes each particle's *rigid* motions, which only the soft polymer
// resists, 1e4 times too slow. So:
//
//   P = D^-1                                   on dofs outside fully free particles,
//   P = (I - Q Q^T) D^-1 (I - Q Q^T) + Q Q^T / h   on each fully free particle's 3 n_p dofs,
//
// with D the diagonal of the springs' and cells' stiffness terms linearised at a state
// (stiffness_terms.hpp; at rest: springs sum k e_a^2 over a node's springs, e the rest direction;
// volume force factor x kappa l_e / 16 per cell at the node), Q an orthonormal basis of the
// particle's 6 rigid motions (3 translations, 3 rotations about its centre) and h the mean
// polymer diagonal (the rigid modes are resisted by the polymer alone). P is symmetric positive
// definite.
//
// With `multilevel`, P + C: the additive correction over coarse grids of the lattice
// (multilevel_correction.hpp), which carries the polymer's long and middle waves that the
// diagonal leaves slow. Also symmetric positive definite. Where the lattice holds no coordinate
// (so C would be singular) it is left out.
//
// Node blocks. Where P is built at a state (the multilevel preconditioner, below), each polymer
// node whose three coordinates are free takes the inverse of its 3 x 3 block of the stiffness
// terms (the sum of c u u^T over its springs and c g_v g_v^T over its cells) in place of the
// inverse of that block's diagonal (NodeScaling::blocks, the default). In contact the polymer
// between the particles is compressed and sheared, so a node's stiffness is strongly
// anisotropic with principal directions off the lattice axes, which a diagonal cannot describe:
// on four steps of the full-size Fig. 4.11 loop the blocks took 12-21 % fewer L-BFGS iterations,
// 9 % fewer over the whole loop (docs/performance.md, "Node blocks in the multilevel
// preconditioner"). Each block is a sum of
// positive semi-definite terms; one that is not safely positive definite (its Cholesky factor's
// smallest pivot below 1e-8 of its largest diagonal entry) keeps its diagonal. So P stays
// symmetric positive definite. The blocks' off-diagonal entries cost 32 bytes per node (the
// diagonal of each inverse block takes the place of D^-1). NodeScaling::diagonal keeps the
// diagonal everywhere (the preconditioner before the blocks, kept to measure against). Built at
// rest, P has the diagonal whatever the choice: at rest an interior node's springs and cells
// are symmetric about it, and its block is diagonal.
//
// Built at rest (the reference lattice), P depends only on the lattice, the free coordinates and
// the force scale, so a run relaxing many steps keeps one (PreconditionerCache,
// preconditioner_cache.hpp) while its free coordinates stay: the plain P of `method = "lbfgs"`
// and of small lattices. With the multilevel correction it is built at a state instead: large
// lattices are where particles in contact deform the polymer far from its rest shape. The cache
// builds it at a relaxation's start and keeps it while the state stays close to where it was
// built.

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <vector>

#include "mresim/mess/solvers/contact_gap.hpp"
#include "mresim/mess/solvers/contact_gap_blocks.hpp"
#include "mresim/mess/solvers/multilevel_correction.hpp"
#include "mresim/mess/solvers/node_scaling.hpp"
#include "mresim/mess/system/constraints.hpp"
#include "mresim/mess/system/system_energy.hpp"

namespace mresim::mess {

class RigidParticlePreconditioner {
 public:
  // Diagonal from the lattice's springs and cells; scaled like the minimiser's variables
  // (gradient in units of force_scale per l_e): D_scaled = D l_e / force_scale.
  // `state`: the positions (3 x N, m) at which springs and cells are linearised
  // (stiffness_terms.hpp) and the particles' rigid motions taken; null: the reference lattice.
  // `processes`: the MPI processes that share the multilevel correction's build
  // (multilevel_correction.hpp; collective on them), null: this process alone.
  // `node_scaling`: used where `state` is given (header). `contact_gap`: where `state` is given,
  // whether the polymer between particles in contact is solved exactly (contact_gap_blocks.hpp:
  // the gaps of the system's current positions, where the minimisers build P).
  RigidParticlePreconditioner(const MessSystem& system, const DofMap& map, double force_scale,
                              bool multilevel = false, const Eigen::Matrix3Xd* state = nullptr,
                              const detail::BlockSplit* processes = nullptr,
                              NodeScaling node_scaling = NodeScaling::blocks,
                              ContactGap contact_gap = ContactGap::exact);

  // P v. `map`: one with the same free coordinates and groups as the constructor's (as
  // PreconditionerCache hands out); the multilevel correction reads the lattice through it.
  Eigen::VectorXd apply(const DofMap& map, const Eigen::VectorXd& v) const;

  // The multilevel correction, or null (not asked for, or nothing held).
  const MultilevelCorrection* multilevel() const { return multilevel_.get(); }
  // The gaps between particles in contact solved exactly, or null (none, or not asked for).
  const ContactGapBlocks* contact_gaps() const { return contact_gaps_.get(); }
  // Nodes scaled by the inverse of their 3 x 3 block (header).
  [[nodiscard]] Eigen::Index block_nodes() const {
    return static_cast<Eigen::Index>(node_blocks_.size());
  }

 private:
  // D^-1 (only the inverse is kept: 24 bytes per node); on a block node the diagonal of its
  // inverse block.
  Eigen::VectorXd inverse_diagonal_;
  // A node scaled by its inverse block B^-1: its first dof (its coordinates are dofs first,
  // first + 1, first + 2) and B^-1's off-diagonal entries.
  struct NodeBlock {
    std::int64_t first = 0;
    double xy = 0.0;
    double xz = 0.0;
    double yz = 0.0;
  };
  std::vector<NodeBlock> node_blocks_;
  // Fills blocks_: the rigid-motion bases of the particles at positions x (3 x N, m).
  void add_particle_blocks(const lattice::Lattice& lat, const DofMap& map,
                           const Eigen::Matrix3Xd& x);
  // Fills node_blocks_ (and their entries of inverse_diagonal_) from the stiffness terms'
  // diagonal and off-diagonal entries per node (N/m; scaled by `scale`).
  void invert_node_blocks(const lattice::Lattice& lat, const DofMap& map,
                          const Eigen::Matrix3Xd& diagonal, const Eigen::Matrix3Xd& off,
                          double scale);
  double rigid_stiffness_ = 1.0;
  struct Block {
    std::vector<Eigen::Index> dofs;  // 3 n_p, node by node
    Eigen::MatrixXd q;               // 3 n_p x 6, orthonormal
  };
  std::vector<Block> blocks_;
  std::unique_ptr<MultilevelCorrection> multilevel_;
  std::unique_ptr<ContactGapBlocks> contact_gaps_;
};

}  // namespace mresim::mess
