#pragma once

// The L-BFGS memory of the 3D minimiser (minimiser.cpp): the last m steps s and gradient
// changes y, and the product of the inverse-Hessian approximation with a vector by the two-loop
// recursion (Nocedal & Wright, Alg. 7.4), H0 = (s.y / y.P y) P with the newest pair and a
// preconditioner P.
//
// At full size each stored vector is 24 bytes per node and the 2m vectors (m = 10 by default)
// are the largest part of a run's memory, and the recursion sweeps all of them every iteration.
// So a full memory takes a new pair into the storage of the oldest one (it never holds more than
// m pairs), and the recursion runs on both cores over fixed blocks (vector_algebra.hpp), each
// update fused with the next dot product: 2m + 1 sweeps over q instead of 4m, bitwise the same
// result for any number of threads. H0's scale needs P y of the newest pair: it is computed once
// per new pair (or after forget_scale(), when P may have changed), not on every product.
//
// The pairs can be stored in single precision (set_precision): half the memory and half the
// bytes the recursion sweeps. The recursion then runs on the stored pairs exactly as if they
// were the pairs: s.y and y.y are formed from the stored values (in double), so the operator
// is the L-BFGS operator of those pairs, symmetric positive definite whenever every s.y > 0;
// only the curvature information it carries is rounded to 6e-8 relative. q and all sums stay
// in double.
//
// Over MPI processes (set_split, docs/mpi.md) each process stores only its own blocks of s and
// y, about 1/P of the memory, and sweeps only those in the recursion; each dot product's block
// sums are shared (BlockSplit) and added in block order, and q is shared whole before P is
// applied and at the end. The product is then bitwise the single-process one, on every process.

#include <Eigen/Core>
#include <deque>
#include <functional>
#include <memory>

#include "mresim/mess/solvers/block_split.hpp"

namespace mresim::mess::detail {

// How the pairs are stored.
enum class LbfgsPrecision { double_precision, single_precision };

class LbfgsMemory {
 public:
  using Preconditioner = std::function<Eigen::VectorXd(const Eigen::VectorXd&)>;

  bool empty() const { return rho_.empty(); }
  int size() const { return static_cast<int>(rho_.size()); }
  void clear();
  // Clears the memory when the precision changes.
  void set_precision(LbfgsPrecision precision);
  [[nodiscard]] LbfgsPrecision precision() const { return precision_; }
  // The preconditioner may have changed (a new inner run): H0's scale is computed again.
  void forget_scale() { scale_known_ = false; }

  // Keep only this process's blocks from now on (null: the whole vectors); clears the memory.
  // Every process of the split must then make the same calls with the same whole vectors.
  void set_split(std::shared_ptr<const BlockSplit> split);
  // Entries held in the stored pairs (2 x size() x the owned length), and their bytes.
  [[nodiscard]] Eigen::Index stored_entries() const;
  [[nodiscard]] Eigen::Index stored_bytes() const;

  // Keeps the pair s = alpha d, y = g_new - g_old if it has positive curvature
  // (s.y > 1e-12 |y|^2), dropping the oldest pairs beyond `capacity`.
  void add(double alpha, const Eigen::VectorXd& d, const Eigen::VectorXd& g_new,
           const Eigen::VectorXd& g_old, int capacity);

  // H g (H0 = P without pairs).
  Eigen::VectorXd times(const Eigen::VectorXd& g, const Preconditioner& P);

 private:
  template <class Stored>
  void add_to(std::deque<Stored>& S, std::deque<Stored>& Y, double alpha, const Eigen::VectorXd& d,
              const Eigen::VectorXd& g_new, const Eigen::VectorXd& g_old, int capacity);
  template <class Stored>
  Eigen::VectorXd times_with(const std::deque<Stored>& S, const std::deque<Stored>& Y,
                             const Eigen::VectorXd& g, const Preconditioner& P);
  void drop_oldest();
  [[nodiscard]] OwnedBlocks owned(Eigen::Index n) const;
  // sum over all blocks b of block(begin_b, length_b), each process computing its own blocks'
  // terms (block(...) sees global indices), added in block order.
  template <class Block>
  double sum_owned(Eigen::Index n, Block&& block) const;
  LbfgsPrecision precision_ = LbfgsPrecision::double_precision;
  // The pairs, in S_ and Y_ (double precision) or Sf_ and Yf_ (single); the others are empty.
  std::deque<Eigen::VectorXd> S_;
  std::deque<Eigen::VectorXd> Y_;
  std::deque<Eigen::VectorXf> Sf_;
  std::deque<Eigen::VectorXf> Yf_;
  std::deque<double> rho_;  // 1 / (s.y)
  double scale_ = 1.0;      // s.y / y.P y of the newest pair, once scale_known_
  bool scale_known_ = false;
  std::shared_ptr<const BlockSplit> split_;
  Eigen::Index offset_ = 0;  // global index of the stored vectors' first entry
};

}  // namespace mresim::mess::detail
