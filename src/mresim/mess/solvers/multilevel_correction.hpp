#pragma once

// The multilevel part of the minimisers' preconditioner (preconditioner.hpp): an additive
// correction over a hierarchy of coarse grids of the lattice (Bramble, Pasciak and Xu, "Parallel
// multilevel preconditioners", Math. Comp. 55, 1990):
//
//   C v = sum_l Phi_l B_l Phi_l^T v,
//
// Phi_l the trilinear interpolation from coarse grid l to the free node coordinates, A the
// springs' and cells' stiffness terms linearised at a state (stiffness_terms.hpp: at rest the
// elastic Hessian; the matrix whose diagonal RigidParticlePreconditioner inverts),
// B_l = diag(Phi_l^T A Phi_l)^-1 on every level but the coarsest and B_L = (Phi_L^T A Phi_L)^-1
// on the coarsest (a sparse LDL^T).
//
// Why. The rigid-particle preconditioner is a diagonal scaling plus the particles' rigid
// motions, so the polymer's long and middle waves keep the conditioning of a diagonally scaled
// Laplacian, which worsens like the lattice's width squared: L-BFGS's iterations grew with the
// lattice (docs/performance.md). Each level carries the waves of its own length; the sum is
// known to condition a grid Laplacian independently of the grid's size.
//
// The grids. Level 1 takes every second lattice plane along each axis and the last one, level
// l + 1 every second plane of level l and its last one, so the grids are nested and Phi_l is
// the composition of the levels' own linear interpolations. Coarsening stops at the first
// level with at most `exact_limit` coarse coordinates, which is solved exactly.
//
// Cost. Applying C restricts v level by level (one sweep per axis, each halving the data; the
// first reads v in place), scales, solves the coarsest level and interpolates back (the last
// sweep adds into w): about 3.5 ms at 285k nodes on 2 threads, a sixth of an energy evaluation
// (bench/preconditioner_bench.cpp). Each sweep works on whole slices of the grid (a node's
// three values along z, a z-line along x, a y-plane along y), each coarse value summing its
// terms in a register in the order of the finer line; the slices are split over the threads,
// so the result is bitwise the same for any number of threads. Memory: the levels' inverse
// diagonals (about 3 bytes per node) and the coarsest level's factor (about 23 bytes per node
// at 285k nodes); while C is applied, the sweeps' transient arrays (18 bytes per node) and the
// levels' fields. The free coordinates are read through the minimiser's DofMap, which add_to()
// is given, instead of a copy of its map. Building it sweeps the lattice's springs and cells
// once (each a rank-one term: stiffness_terms.hpp), projecting each term onto the 3 x 3 x 3
// points around it on every level; the coarsest level also sums the lower triangle of its
// neighbour blocks (all its sparse factor reads), the larger part of the build. The threads
// split each level's points along z, each sweeping the terms that reach its own points (a band
// of lattice layers), so every sum takes its terms in index order whatever the number of
// threads: about 6 s at 993k nodes on 2 threads of a slow machine, 8.5 s there when each thread
// built whole levels (bench/preconditioner_bench.cpp, docs/performance.md). It depends on the
// lattice, the free coordinates, the force scale and the state; a run builds one at a
// relaxation's starting state and keeps it while the lattice stays close to that state
// (PreconditionerCache, preconditioner_cache.hpp).
//
// Over MPI processes (a BlockSplit of more than one process, docs/mpi.md) the levels are
// built by different processes, each level by one, the coarsest by the first, and shared
// whole: every process then holds the same correction, bitwise the single-process one (each
// level's sums come in the same order, and every process factors the same coarsest matrix).
// Applying it is not split: every process applies it whole to the same whole vector.

#include <Eigen/Core>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <array>
#include <cstdint>
#include <vector>

#include "mresim/mess/lattice/lattice.hpp"
#include "mresim/mess/solvers/block_split.hpp"
#include "mresim/mess/system/constraints.hpp"

namespace mresim::mess {

class MultilevelCorrection {
 public:
  // The largest coarsest level solved exactly (coordinates). 10,000 takes the Fig. 4.25
  // helix's (66 x 66 x 228 nodes) third level, 10 x 10 x 30 points, instead of its fourth: its
  // strained steps need 1.33x fewer iterations and run 1.26x faster, for 60 MB more peak
  // memory (docs/performance.md, "A finer exact level for the helix"). The other
  // chapter 4 lattices are bound by the 1/64 rule of build_levels and keep their levels.
  static constexpr Eigen::Index kDefaultExactLimit = 10000;

  // Scaled like the minimiser's variables (RigidParticlePreconditioner): A l_e / force_scale.
  // `volume_force_factor`: the volume term's force factor (MessSettings::elastic).
  // Throws std::invalid_argument if exact_limit < 1, std::runtime_error if the coarsest level
  // cannot be factored (no coordinate held, so A is singular: callers leave the correction out).
  // `state`: the positions (3 x N, m) at which the springs and cells are linearised
  // (stiffness_terms.hpp); null: the reference lattice. `processes`: the processes that share
  // the build (collective on them; every one must pass the same arguments), null: this one.
  MultilevelCorrection(const lattice::Lattice& lattice, double volume_force_factor,
                       const DofMap& map, double force_scale,
                       const Eigen::Matrix3Xd* state = nullptr,
                       Eigen::Index exact_limit = kDefaultExactLimit,
                       const detail::BlockSplit* processes = nullptr);

  // w += C v (v, w over the map's dofs). `map`: one with the same free coordinates as the
  // constructor's (PreconditionerCache keys on them); std::invalid_argument if its number of
  // own dofs differs.
  void add_to(const DofMap& map, const Eigen::VectorXd& v, Eigen::VectorXd& w) const;

  int levels() const { return static_cast<int>(levels_.size()); }
  // The grid points (along x, y, z) of each level a lattice of `nodes` points gets, finest
  // first, the last solved exactly: what the constructor builds, without building it.
  static std::vector<std::array<int, 3>> level_points(const std::array<int, 3>& nodes,
                                                      Eigen::Index exact_limit);
  // Coarse coordinates of level l (1-based, as in the header): 3 x its grid points.
  Eigen::Index level_size(int level) const;

 private:
  // One axis of a level: the lattice plane of each point, and for each point of the next finer
  // level (the lattice for level 1) the lower of its two bracketing points here and the weight
  // of the upper one. The restriction's terms by coarse point j: term_begin[j] ..
  // term_begin[j + 1] index term_fine (the finer point) and term_weight, in increasing finer
  // point, so that each coarse value adds its terms in the order of a sweep over the finer line.
  struct Axis {
    std::vector<int> plane;
    std::vector<int> lower;
    std::vector<double> upper;
    std::vector<int> term_begin;
    std::vector<int> term_fine;
    std::vector<double> term_weight;
  };
  struct Level {
    std::array<Axis, 3> axes;
    std::array<int, 3> points{};
    // 3 x points: diag(Phi^T A Phi)^-1 (0 where no free coordinate reaches), coarsest: unused.
    Eigen::VectorXd inverse_diagonal;
  };

  static std::vector<Level> build_levels(const std::array<int, 3>& fine, Eigen::Index exact_limit);
  static void add_restriction_terms(Axis& axis, int points);
  void assemble(const lattice::Lattice& lattice, double volume_force_factor, double scale,
                const DofMap& map, const Eigen::Matrix3Xd* state,
                const detail::BlockSplit* processes);
  // Over several processes: each level's result from the process that built it (owner), sent
  // to the others; `coarsest` holds the coarsest level's diagonal and blocks on its owner,
  // `failed` the levels whose build failed here. If a level failed, the others throw
  // std::runtime_error and its owner returns (to rethrow its own error).
  void share_levels(const std::vector<int>& owner, const detail::BlockSplit& processes,
                    std::vector<double>& coarsest, const std::vector<char>& failed);
  // The coarsest level's matrix from its diagonal and neighbour blocks (LevelAssembler), and
  // its LDL^T; throws std::runtime_error if it is singular.
  void factor_coarsest(const std::array<int, 3>& points, const std::vector<double>& diagonal,
                       const std::vector<double>& blocks);

  std::array<int, 3> fine_{};
  Eigen::Index own_dofs_ = 0;  // the constructor's map's (checked in add_to)
  std::vector<Level> levels_;
  std::vector<Eigen::Index> exact_index_;  // coarsest level: 3 J + a -> row of the factor, or -1
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> factor_;
};

}  // namespace mresim::mess
