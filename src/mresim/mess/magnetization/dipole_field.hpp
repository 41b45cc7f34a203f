#pragma once

// Point-dipole fields between the particles of the 3D model (Section 4.2.3, eq. 4.57):
//   H_dip(r_ij) = V/(4 pi) [3 r^ (M_j . r^) - M_j] / r^3 = D(r_ij) M_j,  r_ij = r_i - r_j,
// so the total dipolar field at particle i is sum_{j != i} D(r_ij) M_j (the sum in eq. 4.58).
// D is symmetric, even in r and traceless; it is dimensionless, so the same tensor maps
// reduced magnetizations m = M/Ms to reduced fields h = H/Ms.
//
// Geometry enters only through a list of interacting pairs, each with its displacement
// vector. OpenBoundary below builds the list of the dissertation's free block (every pair
// once, no cut-off). A periodic cell becomes another policy that returns one entry per
// interacting (particle, image) pair, including entries with i == j for a particle and its
// own images (one entry per +-L pair); the field, the solver and the energies then need no
// change. (Dipole lattice sums converge only conditionally: a periodic policy must be an
// Ewald-type sum, not a plain truncation.)

#include <Eigen/Core>
#include <vector>

namespace mresim::magnetism {

// One interacting pair: particle i and (an image of) particle j, r = displacement from that
// image of j to i. Every unordered interaction appears exactly once in a pair list.
struct ParticlePair {
  int i = 0;
  int j = 0;
  Eigen::Vector3d r = Eigen::Vector3d::Zero();
};

using PairList = std::vector<ParticlePair>;

// Displacement policy of the free block: pairs (i, j), i < j, in lexicographic order,
// r = r_i - r_j. Centres are the columns of `centres` (m).
struct OpenBoundary {
  PairList pairs(const Eigen::Matrix3Xd& centres) const;
};

// Eq. 4.57's tensor D(r) = V/(4 pi |r|^3) (3 r^ r^T - I). Throws std::invalid_argument for
// r = 0 (coincident centres) or a non-finite r.
Eigen::Matrix3d dipole_tensor(const Eigen::Vector3d& r, double volume);

// The dipolar coupling of one configuration: the tensors of every pair, built once and reused
// by every iteration of the magnetization solve (the original builds its dense 3N x 3N matrix
// once per call, docs/original-code.md#magnetization).
class DipoleCoupling {
 public:
  DipoleCoupling(int particle_count, PairList pairs, double volume);
  // Free block (OpenBoundary).
  static DipoleCoupling open(const Eigen::Matrix3Xd& centres, double volume);

  int particle_count() const { return particle_count_; }
  const PairList& pairs() const { return pairs_; }
  const std::vector<Eigen::Matrix3d>& tensors() const { return tensors_; }

  // Dipolar field at every particle, H_i = sum_pairs D M_j (and D M_i at j), in the units of
  // M. Linear in M, so this is also its own Jacobian-vector product. Sums run in the fixed
  // order of the pair list (results do not depend on the thread count).
  Eigen::Matrix3Xd field(const Eigen::Matrix3Xd& M) const;

  // The same map as a dense symmetric 3N x 3N matrix (block (i, j) = D(r_ij)), for Newton
  // steps and stability checks.
  Eigen::MatrixXd dense() const;

 private:
  int particle_count_;
  PairList pairs_;
  std::vector<Eigen::Matrix3d> tensors_;
};

// Convenience: eq. 4.57 summed over all other particles for the free block (A/m for M in A/m).
Eigen::Matrix3Xd dipole_fields(const Eigen::Matrix3Xd& centres, const Eigen::Matrix3Xd& M,
                               double volume);

}  // namespace mresim::magnetism
