// The L-BFGS memory (lbfgs_memory.hpp): its blocked, fused two-loop recursion gives the product
// of the textbook serial recursion (to rounding), bitwise the same for any number of threads;
// pairs without positive curvature are refused, the oldest pair goes beyond the capacity, and
// H0's scale costs one preconditioner application per new pair. Pairs stored in single
// precision give the recursion of the rounded pairs.

#include "mresim/mess/solvers/lbfgs_memory.hpp"

#include <gtest/gtest.h>
#include <omp.h>

#include <random>
#include <vector>

#include "mresim/mess/system/fixed_order.hpp"

namespace mresim::mess::detail {
namespace {

Eigen::VectorXd random_vector(Eigen::Index n, std::mt19937_64& random) {
  std::normal_distribution<double> normal;
  Eigen::VectorXd v(n);
  for (Eigen::Index k = 0; k < n; ++k) v[k] = normal(random);
  return v;
}

struct Pair {
  Eigen::VectorXd s;
  Eigen::VectorXd y;
};

// N&W Alg. 7.4 with Eigen's serial algebra, H0 = (s.y / y.P y) P of the newest pair.
Eigen::VectorXd serial_two_loop(const std::vector<Pair>& pairs, const Eigen::VectorXd& g,
                                const Eigen::VectorXd& p_diagonal) {
  Eigen::VectorXd q = g;
  std::vector<double> a(pairs.size());
  for (int k = static_cast<int>(pairs.size()) - 1; k >= 0; --k) {
    const Pair& p = pairs[static_cast<std::size_t>(k)];
    a[static_cast<std::size_t>(k)] = p.s.dot(q) / p.s.dot(p.y);
    q -= a[static_cast<std::size_t>(k)] * p.y;
  }
  const Pair& newest = pairs.back();
  q = p_diagonal.cwiseProduct(q) *
      (newest.s.dot(newest.y) / newest.y.dot(p_diagonal.cwiseProduct(newest.y)));
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    const double b = pairs[k].y.dot(q) / pairs[k].s.dot(pairs[k].y);
    q += (a[k] - b) * pairs[k].s;
  }
  return q;
}

// A memory of `count` pairs with y = A s for a diagonal A > 0 (positive curvature), over n
// unknowns, the pairs added as L-BFGS adds them (s = alpha d, y = g_new - g_old).
struct Fixture {
  explicit Fixture(Eigen::Index n, int count, int capacity,
                   LbfgsPrecision precision = LbfgsPrecision::double_precision)
      : random(7) {
    memory.set_precision(precision);
    const Eigen::VectorXd curvature = random_vector(n, random).cwiseAbs().array() + 0.5;
    p_diagonal = curvature.cwiseInverse();
    for (int k = 0; k < count; ++k) {
      const Eigen::VectorXd d = random_vector(n, random);
      const double alpha = 0.5 + 0.1 * k;
      const Eigen::VectorXd g_old = random_vector(n, random);
      const Eigen::VectorXd g_new = g_old + curvature.cwiseProduct(alpha * d);
      memory.add(alpha, d, g_new, g_old, capacity);
      pairs.push_back({alpha * d, g_new - g_old});
    }
    while (static_cast<int>(pairs.size()) > capacity) pairs.erase(pairs.begin());
    preconditioner = [this](const Eigen::VectorXd& v) -> Eigen::VectorXd {
      ++applications;
      return p_diagonal.cwiseProduct(v);
    };
  }
  std::mt19937_64 random;
  Eigen::VectorXd p_diagonal;
  LbfgsMemory memory;
  std::vector<Pair> pairs;
  LbfgsMemory::Preconditioner preconditioner;
  int applications = 0;
};

// The memory's product with g on 1, 2, 3 and 8 threads: `expected` to 1e-12, and bitwise the
// same on each.
void expect_product_on_every_thread_count(Fixture& f, const Eigen::VectorXd& g,
                                          const Eigen::VectorXd& expected) {
  const int threads_before = omp_get_max_threads();
  Eigen::VectorXd first;
  for (const int threads : {1, 2, 3, 8}) {
    omp_set_num_threads(threads);
    const Eigen::VectorXd product = f.memory.times(g, f.preconditioner);
    EXPECT_LE((product - expected).norm(), 1e-12 * expected.norm()) << g.size() << " " << threads;
    if (threads == 1) {
      first = product;
    } else {
      EXPECT_TRUE(product == first) << "not bitwise the same with " << threads << " threads";
    }
  }
  omp_set_num_threads(threads_before);
}

TEST(LbfgsMemory, TwoLoopAgreesWithTheSerialRecursionOnEveryThreadCount) {
  // Below one summation block, across the parallel threshold with a partial last block.
  for (const Eigen::Index n : {Eigen::Index{50}, kParallelMinimum + 4097}) {
    Fixture f(n, 14, 10);  // 14 pairs added, the 10 newest kept
    ASSERT_EQ(f.memory.size(), 10);
    const Eigen::VectorXd g = random_vector(n, f.random);
    const Eigen::VectorXd expected = serial_two_loop(f.pairs, g, f.p_diagonal);
    expect_product_on_every_thread_count(f, g, expected);
  }
}

// Pairs stored in single precision: the product is the recursion of the stored (rounded)
// pairs, to double rounding, on every thread count bitwise the same; it stays within single
// rounding of the double-precision product, and the pairs take half the bytes.
TEST(LbfgsMemory, SinglePrecisionIsTheRecursionOfTheRoundedPairs) {
  for (const Eigen::Index n : {Eigen::Index{50}, kParallelMinimum + 4097}) {
    Fixture f(n, 14, 10, LbfgsPrecision::single_precision);
    const Fixture exact(n, 14, 10);
    ASSERT_EQ(f.memory.size(), 10);
    EXPECT_EQ(f.memory.stored_entries(), 20 * n);
    EXPECT_EQ(2 * f.memory.stored_bytes(), exact.memory.stored_bytes());
    std::vector<Pair> rounded = f.pairs;
    for (Pair& p : rounded) {
      p.s = p.s.cast<float>().cast<double>();
      p.y = p.y.cast<float>().cast<double>();
    }
    const Eigen::VectorXd g = random_vector(n, f.random);
    const Eigen::VectorXd expected = serial_two_loop(rounded, g, f.p_diagonal);
    const Eigen::VectorXd unrounded = serial_two_loop(f.pairs, g, f.p_diagonal);
    // The rounding is visible, and small.
    EXPECT_GT((expected - unrounded).norm(), 1e-12 * unrounded.norm());
    EXPECT_LE((expected - unrounded).norm(), 1e-5 * unrounded.norm());
    expect_product_on_every_thread_count(f, g, expected);
    // A new precision clears the memory.
    f.memory.set_precision(LbfgsPrecision::double_precision);
    EXPECT_TRUE(f.memory.empty());
  }
}

TEST(LbfgsMemory, RefusesPairsWithoutPositiveCurvature) {
  Fixture f(100, 3, 10);
  ASSERT_EQ(f.memory.size(), 3);
  const Eigen::VectorXd d = random_vector(100, f.random);
  const Eigen::VectorXd g_old = random_vector(100, f.random);
  f.memory.add(1.0, d, g_old - d, g_old, 10);  // s.y = -|d|^2 < 0
  f.memory.add(1.0, d, g_old, g_old, 10);      // y = 0
  EXPECT_EQ(f.memory.size(), 3);
  f.memory.clear();
  EXPECT_TRUE(f.memory.empty());
  // Without pairs the product is P g.
  const Eigen::VectorXd g = random_vector(100, f.random);
  EXPECT_TRUE(f.memory.times(g, f.preconditioner) == f.p_diagonal.cwiseProduct(g));
}

TEST(LbfgsMemory, AppliesThePreconditionerToTheNewestPairOncePerPair) {
  Fixture f(200, 4, 10);
  const Eigen::VectorXd g = random_vector(200, f.random);
  (void)f.memory.times(g, f.preconditioner);
  EXPECT_EQ(f.applications, 2);  // P y of the newest pair, then P q
  const Eigen::VectorXd again = f.memory.times(g, f.preconditioner);
  EXPECT_EQ(f.applications, 3);  // P q only
  f.memory.forget_scale();       // a new preconditioner: the scale is computed again
  EXPECT_TRUE(f.memory.times(g, f.preconditioner) == again);
  EXPECT_EQ(f.applications, 5);
}

}  // namespace
}  // namespace mresim::mess::detail
