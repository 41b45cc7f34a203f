#pragma once

// The polymer between two particles in contact, solved exactly in the minimisers' multilevel
// preconditioner (preconditioner.hpp): P + sum_g R_g^T H_g^-1 R_g, with R_g the free
// coordinates of gap g's polymer nodes and H_g their block of the exact elastic Hessian (springs
// and cells, eqs. 4.62 and 4.64, with their force factors) at the state the preconditioner is
// built at.
//
// Why. Between two particles in contact the polymer is squeezed into a gap of about one lattice
// spacing, and its compressed springs (whose Hessian k (1 - L/l) (I - u u^T) is negative) make
// its shear and buckling modes soft. Those are the slowest modes of the preconditioned Hessian:
// on the Fig. 4.11 pair in contact at n_d = 3 the three smallest Ritz values of P H (about
// 5e-4 of the largest) had 44-78 % of their weight in a disc of polymer about the pair's
// midpoint, 0.4 % of the box (bench/preconditioned_spectrum_bench.cpp). The diagonal or node
// blocks cannot describe them, and the coarse levels, built from the positive stiffness terms,
// do not see them. Solving the gap exactly takes them out: conjugate gradients on P H needed
// 1.65x fewer iterations for six decades there, and L-BFGS 2.1-2.4x fewer on single full-size
// steps in contact (docs/performance.md, "The polymer between particles in contact").
//
// Where. The gaps are found, and their blocks taken, at the state the preconditioner is built
// at: the positions of the relaxation's start, or of an earlier one's where the minimisers keep
// the preconditioner (PreconditionerCache, preconditioner.hpp).
//
// Which gaps. A pair of particles whose centres (the mean of their nodes) are less than
// kContactSeparation radii apart, i.e. less than one radius of polymer between their surfaces.
// Its gap: the polymer nodes with all three coordinates free dofs of their own that lie within
// kGapHalfLength radii of the pair's midpoint along its axis and within kGapRadius radii of the
// axis. On the full-size Fig. 4.11 lattice (R = 5.5 l_e) that is about 2,000 nodes. A gap whose
// block is not positive definite (its sparse Cholesky factor fails) is left out, so P stays
// symmetric positive definite.
//
// Cost. The block is assembled from one sweep of the system's elastic Hessian blocks per gap
// (only where a pair is in contact; 27 blocks per gap node while it is summed), in which the
// springs and cells without a gap node are skipped (HessianBlockSink::takes_node: the full-size
// helix spent about 6 s per step computing the whole lattice's blocks for its gaps before, now
// a few hundredths), one gap per thread where there are several, and
// factored with a sparse Cholesky factor (Eigen's SimplicialLLT, AMD ordering) in single
// precision: on the full-size Fig. 4.11 lattice in contact 6,951 coordinates and 2.46 million
// entries of L, 20 MB (69 bytes per lattice node; 30 MB in double). Applying it is a forward
// and a back substitution through L in double precision (so the operator is symmetric to double
// rounding), each split into two branches of the factor's elimination tree that two threads
// solve at once and a trunk solved after (forward) or before (backward) them
// (split_cholesky_solve.hpp); the result does not depend on the number of threads.

#include <Eigen/Core>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

#include "mresim/mess/solvers/split_cholesky_solve.hpp"
#include "mresim/mess/system/constraints.hpp"
#include "mresim/mess/system/system_energy.hpp"

namespace mresim::mess {

class ContactGapBlocks {
 public:
  static constexpr double kContactSeparation = 3.0;  // centre distance, particle radii
  static constexpr double kGapHalfLength = 1.0;      // along the pair's axis, radii
  static constexpr double kGapRadius = 5.0 / 3.0;    // from the axis, radii

  // The gaps of the system at positions `at` (3 x N, m), scaled like the preconditioner's
  // variables (H l_e / force_scale). `map`: the minimiser's.
  ContactGapBlocks(const MessSystem& system, const DofMap& map, double force_scale,
                   const Eigen::Matrix3Xd& at);

  // The particle pairs (p < q, in order) that get a gap: `centres` (the mean of their nodes,
  // 3 x N_p) less than kContactSeparation radii apart.
  static std::vector<std::pair<int, int>> contact_pairs(const Eigen::Matrix3Xd& centres,
                                                        double particle_radius);

  // w += sum_g R_g^T H_g^-1 R_g v (v, w over the map's dofs).
  void add_to(const Eigen::VectorXd& v, Eigen::VectorXd& w) const;

  // Gaps solved exactly, and the dofs they hold in all.
  [[nodiscard]] std::size_t gaps() const { return gaps_.size(); }
  [[nodiscard]] Eigen::Index dofs() const;
  // Gaps found but left out (their block not positive definite).
  [[nodiscard]] int left_out() const { return left_out_; }
  // Gap g's factor and the split of its solves (tests and bench/contact_gap_bench.cpp).
  [[nodiscard]] const Eigen::SimplicialLLT<Eigen::SparseMatrix<float>>& factor(
      std::size_t g) const {
    return *gaps_.at(g).factor;
  }
  [[nodiscard]] const detail::SplitCholeskySolve& solves(std::size_t g) const {
    return gaps_.at(g).solves;
  }

 private:
  struct Gap {
    std::vector<Eigen::Index> dofs;  // the map's dof of each local coordinate
    std::unique_ptr<Eigen::SimplicialLLT<Eigen::SparseMatrix<float>>> factor;
    detail::SplitCholeskySolve solves;  // the factor's solves on two threads
  };
  // The polymer nodes of the gap between particles centred at `first` and `second` (header),
  // at positions `x`.
  static std::vector<std::int64_t> gap_nodes(const MessSystem& system, const DofMap& map,
                                             const Eigen::Matrix3Xd& x,
                                             const Eigen::Vector3d& first,
                                             const Eigen::Vector3d& second);
  // Gap `gap` between the particles centred at `first` and `second`: its dofs, and its factor
  // if its block is positive definite (then true).
  static bool build_gap(const MessSystem& system, const DofMap& map, double force_scale,
                        const Eigen::Matrix3Xd& at, const Eigen::Vector3d& first,
                        const Eigen::Vector3d& second, Gap& gap);
  std::vector<Gap> gaps_;
  int left_out_ = 0;
};

}  // namespace mresim::mess
