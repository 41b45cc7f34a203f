#pragma once

// The L-BFGS memory of the 3D minimiser (minimiser.cpp): the last m steps s with the
// preconditioned gradient changes z = P y, and the product of the inverse-Hessian approximation
// H with a vector, H0 = gamma P with a preconditioner P and gamma = s.y / y.P y of the newest
// pair (Nocedal & Wright, eq. 7.20, with P in place of the identity).
//
// The product in compact form (Byrd, Nocedal & Schnabel 1994, Theorem 2.2): with S and Y the
// pairs as columns, R the upper triangle of S^T Y (R_ij = s_i.y_j, i <= j), D its diagonal and
// Z = P Y (P symmetric),
//
//   H g = gamma P g + S p - gamma Z a,   a = R^-1 S^T g,
//                                        p = R^-T ((D + gamma Y^T Z) a - gamma Z^T g),
//
// in exact arithmetic the two-loop recursion's product (N&W Alg. 7.4). Why not the recursion:
// its H0 needs P y of the newest pair, one more application of P per iteration besides P q
// (about 3 ms at full size with the multilevel correction, more with the contact gap's solves,
// against 30-50 ms for a whole iteration; docs/performance.md, "One application of the
// preconditioner per iteration"). Here P is applied to g itself, and the newest pair's z comes
// without applying P: L-BFGS takes its products in order, at g_k, then at g_{k+1} after adding
// the pair y = g_{k+1} - g_k, so z = P g_{k+1} - P g_k, the difference of the two products'
// P g (P is linear). The memory keeps the last product's P g for that, one whole vector. Where
// that order is not kept, the pair's z is formed by applying P to its y, as the recursion did
// for its scale: after new_objective() (the caller's word that the next product is taken on
// another objective: a new inner run, whose gradient differs at the same point), and wherever
// a fingerprint (64 spread entries' bits) of the last product's g or of the newest pair's end
// g_new does not match (a caller that takes products out of order). The fingerprint alone
// cannot tell an objective that changed only on a few entries (the seed's correction load is
// nonzero only on the particles' nodes), hence new_objective().
//
// At full size each stored vector is 24 bytes per node (12 in single precision) and the 2m
// vectors (m = 10 by default) are the largest part of a run's memory. A full memory takes a new
// pair into the storage of the oldest one. A product reads each pair twice, on both cores over
// fixed blocks (vector_algebra.hpp): one pass per pair for its dot products with g (and the new
// pair's entries of the small matrices), one per pair for the sum; every sum is bitwise the
// same for any number of threads. (Passes over all pairs at once, block by block, streamed from
// memory at half the speed, measured.) The small matrices (m x m) are kept between products.
//
// While a pair waits for its z (between add() and the next product) its y is held in the
// storage its z will take.
//
// The pairs can be stored in single precision (set_precision): half the memory and half the
// bytes the products sweep. Every dot product is formed from the stored (rounded) values, in
// double, and P g, the product and all sums stay in double; s and z are rounded independently (z
// from P g_new - P g_old, not from the rounded y), so the operator is that of the rounded pairs to
// single rounding (6e-8 relative) only.
//
// Over MPI processes (set_split, docs/mpi.md) each process stores only its own blocks of s and
// z, about 1/P of the memory, and sweeps only those; each dot product's block sums are shared
// (BlockSplit) and added in block order, and the product is shared whole at the end. P is
// applied to whole vectors on every process. The product is then bitwise the single-process
// one, on every process.

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <vector>

#include "mresim/mess/solvers/block_split.hpp"
#include "mresim/mess/system/fixed_order.hpp"

namespace mresim::mess::detail {

// How the pairs are stored.
enum class LbfgsPrecision { double_precision, single_precision };

class LbfgsMemory {
 public:
  using Preconditioner = std::function<Eigen::VectorXd(const Eigen::VectorXd&)>;

  bool empty() const { return z_known_.empty(); }
  int size() const { return static_cast<int>(z_known_.size()); }
  // Drops the pairs (the last product's P g stays: it depends on P alone).
  void clear();
  // Clears the memory when the precision changes.
  void set_precision(LbfgsPrecision precision);
  [[nodiscard]] LbfgsPrecision precision() const { return precision_; }
  // P will be another operator from now on: the pairs hold P y, so they are dropped, and so is
  // the last product's P g.
  void preconditioner_changed();
  // The next product is taken on another objective (its gradient may differ at the newest
  // pair's end): the newest pair's z will be formed by applying P, and the last product's P g
  // is forgotten. The pairs stay.
  void new_objective() {
    newest_by_difference_ = false;
    last_pg_known_ = false;
  }

  // Keep only this process's blocks from now on (null: the whole vectors); clears the memory.
  // Every process of the split must then make the same calls with the same whole vectors.
  void set_split(std::shared_ptr<const BlockSplit> split);
  // Entries held in the stored pairs (2 x size() x the owned length), and their bytes; the last
  // product's P g (one whole vector in double) comes on top.
  [[nodiscard]] Eigen::Index stored_entries() const;
  [[nodiscard]] Eigen::Index stored_bytes() const;

  // Keeps the pair s = alpha d, y = g_new - g_old if it has positive curvature
  // (s.y > 1e-12 |y|^2), dropping the oldest pairs beyond `capacity`.
  void add(double alpha, const Eigen::VectorXd& d, const Eigen::VectorXd& g_new,
           const Eigen::VectorXd& g_old, int capacity);

  // H g (H0 = P without pairs). One application of P when taken in L-BFGS's order (header),
  // one more per pair added since the last product otherwise.
  Eigen::VectorXd times(const Eigen::VectorXd& g, const Preconditioner& P);

 private:
  static constexpr int kFingerprintEntries = 64;
  struct Fingerprint {
    Eigen::Index size = -1;
    std::array<std::uint64_t, kFingerprintEntries> bits{};
    bool operator==(const Fingerprint&) const = default;
  };
  static Fingerprint fingerprint(const Eigen::VectorXd& v);

  template <class Stored>
  void add_to(std::deque<Stored>& S, std::deque<Stored>& Z, double alpha, const Eigen::VectorXd& d,
              const Eigen::VectorXd& g_new, const Eigen::VectorXd& g_old, int capacity);
  template <class Stored>
  Eigen::VectorXd times_with(const std::deque<Stored>& S, std::deque<Stored>& Z,
                             const Eigen::VectorXd& g, const Preconditioner& P);
  // A product's dot products with g: S^T g and Z^T g.
  struct ProductDots {
    Eigen::VectorXd sg;
    Eigen::VectorXd zg;
  };
  // H g = gamma P g + S s + Z z.
  struct ProductCoefficients {
    double gamma = 1.0;
    Eigen::VectorXd s;
    Eigen::VectorXd z;
  };
  template <class Stored>
  ProductDots product_dots(const std::deque<Stored>& S, const std::deque<Stored>& Z,
                           const Eigen::VectorXd& g, const Eigen::VectorXd& r, bool by_difference);
  [[nodiscard]] ProductCoefficients coefficients(const ProductDots& dots) const;
  template <class Stored>
  Eigen::VectorXd product_sum(const std::deque<Stored>& S, std::deque<Stored>& Z,
                              const Eigen::VectorXd& r, bool by_difference,
                              const ProductCoefficients& c) const;
  template <class Scalar>
  void newest_z_block(const Eigen::VectorXd& r, Eigen::Index gb, Eigen::Index l,
                      std::array<double, kSumBlock>& zb) const;
  // Pair j's z = P y (its y held in Z[j]), and its entries of R and Y^T Z.
  template <class Stored>
  void complete_by_applying(const std::deque<Stored>& S, std::deque<Stored>& Z, int j,
                            Eigen::Index n, const Preconditioner& P);
  void drop_oldest();
  [[nodiscard]] OwnedBlocks owned(Eigen::Index n) const;
  // The `count` sums over all blocks b of block(begin_b, length_b, out_b), where out_b points to
  // `count` partial sums of block b that block() sets; each process computes its own blocks'
  // terms (block(...) sees global indices). Each sum is added in block order.
  template <class Block>
  std::vector<double> sums_owned(Eigen::Index n, int count, Block&& block) const;

  LbfgsPrecision precision_ = LbfgsPrecision::double_precision;
  // The pairs, oldest first, in S_ and Z_ (double precision) or Sf_ and Zf_ (single); the
  // others are empty. Z[j] holds pair j's y until its z is known (z_known_[j]).
  std::deque<Eigen::VectorXd> S_;
  std::deque<Eigen::VectorXd> Z_;
  std::deque<Eigen::VectorXf> Sf_;
  std::deque<Eigen::VectorXf> Zf_;
  std::deque<bool> z_known_;
  // sy_(i, j) = s_i.y_j for i <= j (R; its diagonal D is set when a pair is added, the rest when
  // its z is formed); yz_ = Y^T Z, symmetric, set when z is formed.
  Eigen::MatrixXd sy_;
  Eigen::MatrixXd yz_;
  // The last product's P g (whole) and the fingerprint of its g; the newest pair's g_new, and
  // whether its g_old was the last product's g on the same objective (so that its z may come by
  // difference).
  Eigen::VectorXd last_pg_;
  Fingerprint last_g_;
  bool last_pg_known_ = false;
  Fingerprint newest_g_new_;
  bool newest_by_difference_ = false;
  std::shared_ptr<const BlockSplit> split_;
  Eigen::Index offset_ = 0;  // global index of the stored vectors' first entry
};

}  // namespace mresim::mess::detail
