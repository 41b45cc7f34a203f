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

#include <Eigen/Core>
#include <deque>
#include <functional>

namespace mresim::mess::detail {

class LbfgsMemory {
 public:
  using Preconditioner = std::function<Eigen::VectorXd(const Eigen::VectorXd&)>;

  bool empty() const { return S_.empty(); }
  int size() const { return static_cast<int>(S_.size()); }
  void clear();
  // The preconditioner may have changed (a new inner run): H0's scale is computed again.
  void forget_scale() { scale_known_ = false; }

  // Keeps the pair s = alpha d, y = g_new - g_old if it has positive curvature
  // (s.y > 1e-12 |y|^2), dropping the oldest pairs beyond `capacity`.
  void add(double alpha, const Eigen::VectorXd& d, const Eigen::VectorXd& g_new,
           const Eigen::VectorXd& g_old, int capacity);

  // H g (H0 = P without pairs).
  Eigen::VectorXd times(const Eigen::VectorXd& g, const Preconditioner& P);

 private:
  void drop_oldest();

  std::deque<Eigen::VectorXd> S_;
  std::deque<Eigen::VectorXd> Y_;
  std::deque<double> rho_;  // 1 / (s.y)
  double scale_ = 1.0;      // s.y / y.P y of the newest pair, once scale_known_
  bool scale_known_ = false;
};

}  // namespace mresim::mess::detail
