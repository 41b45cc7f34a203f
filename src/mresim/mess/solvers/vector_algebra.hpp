#pragma once

// The solvers' vector algebra on both cores, bitwise independent of the thread count.
//
// At full size a free-coordinate vector holds about a million doubles (8 MB); the Newton
// solver's conjugate gradients (newton.cpp) sweep several per iteration, which done serially
// keeps the second core idle. Here every operation runs over fixed blocks of kSumBlock entries
// (fixed_order.hpp): elementwise updates in parallel, and dot products as one vectorised dot per
// block (Eigen, the same code path for a block of a given length and alignment) whose partial
// sums are added in block order, so the results do not depend on the number of threads. The
// fused form does an update and the next dot product in one sweep, which saves one pass over
// memory.
//
// L-BFGS (minimiser.cpp) uses them for its line-search slopes and steps, and its memory
// (lbfgs_memory.hpp) sums over the same fixed blocks.

#include <Eigen/Core>
#include <algorithm>
#include <cstdint>
#include <vector>

#include "mresim/mess/system/fixed_order.hpp"

namespace mresim::mess::detail {

// Runs block(begin, length) over fixed blocks of [0, n), in parallel for long vectors, and
// returns the sum of the blocks' results in block order.
template <class Block>
double sum_over_blocks(Eigen::Index n, Block&& block) {
  if (n <= 0) return 0.0;
  const Eigen::Index blocks = (n + kSumBlock - 1) / kSumBlock;
  if (blocks == 1) return block(Eigen::Index{0}, n);
  std::vector<double> partial(static_cast<std::size_t>(blocks), 0.0);
#pragma omp parallel for schedule(static) if (n >= kParallelMinimum)
  for (Eigen::Index b = 0; b < blocks; ++b) {
    const Eigen::Index begin = b * kSumBlock;
    partial[static_cast<std::size_t>(b)] =
        block(begin, std::min<Eigen::Index>(kSumBlock, n - begin));
  }
  double total = 0.0;
  for (const double s : partial) total += s;
  return total;
}

// a . b
inline double parallel_dot(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  return sum_over_blocks(a.size(), [&](Eigen::Index begin, Eigen::Index length) {
    return a.segment(begin, length).dot(b.segment(begin, length));
  });
}

// y += alpha x
inline void parallel_axpy(double alpha, const Eigen::VectorXd& x, Eigen::VectorXd& y) {
  (void)sum_over_blocks(y.size(), [&](Eigen::Index begin, Eigen::Index length) {
    y.segment(begin, length) += alpha * x.segment(begin, length);
    return 0.0;
  });
}

// y = x (resized), copied in parallel: at full size a copy is 8 MB.
inline void parallel_copy(const Eigen::VectorXd& x, Eigen::VectorXd& y) {
  y.resize(x.size());
  (void)sum_over_blocks(y.size(), [&](Eigen::Index begin, Eigen::Index length) {
    y.segment(begin, length) = x.segment(begin, length);
    return 0.0;
  });
}

// out = a .* b (resized)
inline void parallel_product(const Eigen::VectorXd& a, const Eigen::VectorXd& b,
                             Eigen::VectorXd& out) {
  out.resize(a.size());
  (void)sum_over_blocks(out.size(), [&](Eigen::Index begin, Eigen::Index length) {
    out.segment(begin, length) = a.segment(begin, length).cwiseProduct(b.segment(begin, length));
    return 0.0;
  });
}

// y *= alpha
inline void parallel_scale(double alpha, Eigen::VectorXd& y) {
  (void)sum_over_blocks(y.size(), [&](Eigen::Index begin, Eigen::Index length) {
    y.segment(begin, length) *= alpha;
    return 0.0;
  });
}

// y = x + beta y
inline void parallel_scale_add(double beta, const Eigen::VectorXd& x, Eigen::VectorXd& y) {
  (void)sum_over_blocks(y.size(), [&](Eigen::Index begin, Eigen::Index length) {
    y.segment(begin, length) = x.segment(begin, length) + beta * y.segment(begin, length);
    return 0.0;
  });
}

// y += alpha x, then returns z . y (one sweep).
inline double parallel_axpy_dot(double alpha, const Eigen::VectorXd& x, Eigen::VectorXd& y,
                                const Eigen::VectorXd& z) {
  return sum_over_blocks(y.size(), [&](Eigen::Index begin, Eigen::Index length) {
    auto yb = y.segment(begin, length);
    yb += alpha * x.segment(begin, length);
    return z.segment(begin, length).dot(yb);
  });
}

// max_i |a_i| (exact in any order).
inline double parallel_max_abs(const Eigen::VectorXd& a) {
  if (a.size() == 0) return 0.0;
  const Eigen::Index blocks = (a.size() + kSumBlock - 1) / kSumBlock;
  std::vector<double> partial(static_cast<std::size_t>(blocks), 0.0);
#pragma omp parallel for schedule(static) if (a.size() >= kParallelMinimum)
  for (Eigen::Index b = 0; b < blocks; ++b) {
    const Eigen::Index begin = b * kSumBlock;
    partial[static_cast<std::size_t>(b)] =
        a.segment(begin, std::min<Eigen::Index>(kSumBlock, a.size() - begin)).cwiseAbs().maxCoeff();
  }
  return *std::max_element(partial.begin(), partial.end());
}

}  // namespace mresim::mess::detail
