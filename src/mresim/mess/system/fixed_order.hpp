#pragma once

// Sums and loops whose results do not depend on the number of OpenMP threads.
//
// Floating-point addition is not associative, so an OpenMP reduction gives results that change
// with the thread count. Here a sum is split into blocks of a fixed size (independent of the
// thread count), each block is summed serially in index order, and the block sums are added
// serially in block order: the same operations in the same order for any number of threads.
// Per-node accumulations avoid races the same way: each node gathers its own contributions in
// a fixed order (see elastic_terms.cpp), so no atomics are needed.

#include <array>
#include <cstdint>
#include <vector>

#include "mresim/core/parallel_exceptions.hpp"

namespace mresim::mess::detail {

inline constexpr std::int64_t kSumBlock = 4096;
// Loops shorter than this run on the calling thread: on small lattices a parallel region costs
// more than it saves (and much more on a loaded machine). The result is the same either way.
inline constexpr std::int64_t kParallelMinimum = 16384;

// body(begin, end) for the fixed blocks [begin, end) of [0, n), in parallel for long ranges.
// For elementwise work (each index written by its own block only): the results are those of a
// serial loop whatever the thread count. `body` must not throw.
template <class Body>
void for_each_block(std::int64_t n, Body&& body) {
  if (n <= 0) return;
  const std::int64_t blocks = (n + kSumBlock - 1) / kSumBlock;
#pragma omp parallel for schedule(static) if (n >= kParallelMinimum)
  for (std::int64_t b = 0; b < blocks; ++b) {
    body(b * kSumBlock, (b + 1) * kSumBlock < n ? (b + 1) * kSumBlock : n);
  }
}

// sum_{i < n} term(i), bitwise independent of the thread count.
template <class Term>
double fixed_order_sum(std::int64_t n, Term&& term) {
  if (n <= 0) return 0.0;
  const std::int64_t blocks = (n + kSumBlock - 1) / kSumBlock;
  std::vector<double> partial(static_cast<std::size_t>(blocks), 0.0);
  ParallelExceptions errors;  // `term` may throw; no exception may leave the region
#pragma omp parallel for schedule(static) if (n >= kParallelMinimum)
  for (std::int64_t b = 0; b < blocks; ++b) {
    errors.run([&] {
      const std::int64_t end = (b + 1) * kSumBlock < n ? (b + 1) * kSumBlock : n;
      double s = 0.0;
      for (std::int64_t i = b * kSumBlock; i < end; ++i) s += term(i);
      partial[static_cast<std::size_t>(b)] = s;
    });
  }
  errors.rethrow();
  double total = 0.0;
  for (const double s : partial) total += s;
  return total;
}

// Two sums at once, each as fixed_order_sum; term(i) returns std::array<double, 2>.
template <class Term>
std::array<double, 2> fixed_order_sums(std::int64_t n, Term&& term) {
  if (n <= 0) return {0.0, 0.0};
  const std::int64_t blocks = (n + kSumBlock - 1) / kSumBlock;
  std::vector<std::array<double, 2>> partial(static_cast<std::size_t>(blocks));
  ParallelExceptions errors;
#pragma omp parallel for schedule(static) if (n >= kParallelMinimum)
  for (std::int64_t b = 0; b < blocks; ++b) {
    errors.run([&] {
      const std::int64_t end = (b + 1) * kSumBlock < n ? (b + 1) * kSumBlock : n;
      std::array<double, 2> s{0.0, 0.0};
      for (std::int64_t i = b * kSumBlock; i < end; ++i) {
        const std::array<double, 2> t = term(i);
        s[0] += t[0];
        s[1] += t[1];
      }
      partial[static_cast<std::size_t>(b)] = s;
    });
  }
  errors.rethrow();
  std::array<double, 2> total{0.0, 0.0};
  for (const auto& s : partial) {
    total[0] += s[0];
    total[1] += s[1];
  }
  return total;
}

}  // namespace mresim::mess::detail
