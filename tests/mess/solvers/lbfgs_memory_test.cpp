// The L-BFGS memory (lbfgs_memory.hpp): its compact-form product gives the product of the
// textbook two-loop recursion (to rounding), bitwise the same for any number of threads, with
// one application of the preconditioner per product when taken in L-BFGS's order (the newest
// pair's P y from the difference of two products' P g) and one more per pair otherwise. Pairs
// without positive curvature are refused, the oldest pair goes beyond the capacity. Pairs
// stored in single precision give the product to single rounding.

#include "mresim/mess/solvers/lbfgs_memory.hpp"

#include <gtest/gtest.h>
#include <omp.h>

#include <memory>
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

// P v = w .* v + 0.3 (v reversed): symmetric positive definite (w >= 1) and not diagonal.
Eigen::VectorXd mixing(const Eigen::VectorXd& w, const Eigen::VectorXd& v) {
  return w.cwiseProduct(v) + 0.3 * v.reverse();
}

// N&W Alg. 7.4 with Eigen's serial algebra, H0 = (s.y / y.P y) P of the newest pair.
Eigen::VectorXd serial_two_loop(const std::vector<Pair>& pairs, const Eigen::VectorXd& g,
                                const Eigen::VectorXd& w) {
  Eigen::VectorXd q = g;
  std::vector<double> a(pairs.size());
  for (int k = static_cast<int>(pairs.size()) - 1; k >= 0; --k) {
    const Pair& p = pairs[static_cast<std::size_t>(k)];
    a[static_cast<std::size_t>(k)] = p.s.dot(q) / p.s.dot(p.y);
    q -= a[static_cast<std::size_t>(k)] * p.y;
  }
  const Pair& newest = pairs.back();
  q = mixing(w, q) * (newest.s.dot(newest.y) / newest.y.dot(mixing(w, newest.y)));
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    const double b = pairs[k].y.dot(q) / pairs[k].s.dot(pairs[k].y);
    q += (a[k] - b) * pairs[k].s;
  }
  return q;
}

// A memory of `count` pairs with y = A s for a diagonal A > 0 (positive curvature), over n
// unknowns, the pairs added as L-BFGS adds them (s = alpha d, y = g_new - g_old) but with no
// product between them, so that each pair's P y is formed by applying P.
struct Fixture {
  explicit Fixture(Eigen::Index n, int count, int capacity,
                   LbfgsPrecision precision = LbfgsPrecision::double_precision)
      : random(7) {
    memory.set_precision(precision);
    curvature = random_vector(n, random).cwiseAbs().array() + 0.5;
    w = random_vector(n, random).cwiseAbs().array() + 1.0;
    for (int k = 0; k < count; ++k) {
      const Eigen::VectorXd d = random_vector(n, random);
      const double alpha = 0.5 + 0.1 * k;
      const Eigen::VectorXd g_old = random_vector(n, random);
      const Eigen::VectorXd g_new = g_old + curvature.cwiseProduct(alpha * d);
      memory.add(alpha, d, g_new, g_old, capacity);
      pairs.push_back({alpha * d, g_new - g_old});
    }
    while (static_cast<int>(pairs.size()) > capacity) pairs.erase(pairs.begin());
    preconditioner = [w = w, count = applications](const Eigen::VectorXd& v) -> Eigen::VectorXd {
      ++*count;
      return mixing(w, v);
    };
  }
  Fixture(const Fixture&) = delete;
  Fixture& operator=(const Fixture&) = delete;
  Fixture(Fixture&&) = delete;
  Fixture& operator=(Fixture&&) = delete;
  ~Fixture() = default;
  [[nodiscard]] int applied() const { return *applications; }
  // The pair from g to g + A (alpha d), added as L-BFGS adds it; g moves to the new point.
  void take_step(double alpha, const Eigen::VectorXd& d, Eigen::VectorXd& g, int capacity) {
    const Eigen::VectorXd g_new = g + curvature.cwiseProduct(alpha * d);
    memory.add(alpha, d, g_new, g, capacity);
    pairs.push_back({alpha * d, g_new - g});
    while (static_cast<int>(pairs.size()) > capacity) pairs.erase(pairs.begin());
    g = g_new;
  }
  // The product at `at`: the recursion's to 1e-12, with `extra` applications of P.
  Eigen::VectorXd checked_product(const Eigen::VectorXd& at, int extra) {
    const int before = applied();
    const Eigen::VectorXd product = memory.times(at, preconditioner);
    EXPECT_EQ(applied(), before + extra);
    const Eigen::VectorXd expected = serial_two_loop(pairs, at, w);
    EXPECT_LE((product - expected).norm(), 1e-12 * expected.norm());
    return product;
  }
  std::mt19937_64 random;
  Eigen::VectorXd curvature;
  Eigen::VectorXd w;
  LbfgsMemory memory;
  std::vector<Pair> pairs;
  std::shared_ptr<int> applications = std::make_shared<int>(0);  // of the preconditioner
  LbfgsMemory::Preconditioner preconditioner;
};

// make_fixture()'s first product with a random g on 1, 2, 3 and 8 threads, each on a fresh
// fixture (so the pairs' P y are formed on that thread count too): `expected(fixture, g)` to
// `tolerance` relative, and bitwise the same on each.
template <class MakeFixture, class Expected>
void expect_product_on_every_thread_count(MakeFixture&& make_fixture, Expected&& expected,
                                          double tolerance) {
  const int threads_before = omp_get_max_threads();
  Eigen::VectorXd first;
  for (const int threads : {1, 2, 3, 8}) {
    omp_set_num_threads(threads);
    Fixture f = make_fixture();
    const Eigen::VectorXd g = random_vector(f.curvature.size(), f.random);
    const Eigen::VectorXd product = f.memory.times(g, f.preconditioner);
    const Eigen::VectorXd reference = expected(f, g);
    EXPECT_LE((product - reference).norm(), tolerance * reference.norm())
        << g.size() << " " << threads;
    if (threads == 1) {
      first = product;
    } else {
      EXPECT_TRUE(product == first) << "not bitwise the same with " << threads << " threads";
    }
  }
  omp_set_num_threads(threads_before);
}

TEST(LbfgsMemory, ProductAgreesWithTheTwoLoopRecursionOnEveryThreadCount) {
  // Below one summation block, across the parallel threshold with a partial last block.
  for (const Eigen::Index n : {Eigen::Index{50}, kParallelMinimum + 4097}) {
    expect_product_on_every_thread_count(
        [n] { return Fixture(n, 14, 10); },  // 14 pairs added, the 10 newest kept
        [](const Fixture& f, const Eigen::VectorXd& g) { return serial_two_loop(f.pairs, g, f.w); },
        1e-12);
  }
}

// Pairs stored in single precision: on every thread count bitwise the same, within single
// rounding of the double-precision product, and the pairs take half the bytes.
TEST(LbfgsMemory, SinglePrecisionGivesTheProductToSingleRounding) {
  for (const Eigen::Index n : {Eigen::Index{50}, kParallelMinimum + 4097}) {
    const Fixture single(n, 14, 10, LbfgsPrecision::single_precision);
    const Fixture exact(n, 14, 10);
    EXPECT_EQ(single.memory.stored_entries(), 20 * n);
    EXPECT_EQ(2 * single.memory.stored_bytes(), exact.memory.stored_bytes());
    expect_product_on_every_thread_count(
        [n] { return Fixture(n, 14, 10, LbfgsPrecision::single_precision); },
        [](const Fixture& f, const Eigen::VectorXd& g) { return serial_two_loop(f.pairs, g, f.w); },
        1e-5);
    // The rounding is visible.
    Fixture rounded(n, 14, 10, LbfgsPrecision::single_precision);
    Fixture unrounded(n, 14, 10);
    ASSERT_EQ(rounded.memory.size(), 10);
    const Eigen::VectorXd g = random_vector(n, rounded.random);
    const Eigen::VectorXd difference = rounded.memory.times(g, rounded.preconditioner) -
                                       unrounded.memory.times(g, unrounded.preconditioner);
    EXPECT_GT(difference.norm(), 1e-12 * g.norm());
  }
  // A new precision clears the memory.
  Fixture f(50, 3, 10, LbfgsPrecision::single_precision);
  f.memory.set_precision(LbfgsPrecision::double_precision);
  EXPECT_TRUE(f.memory.empty());
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
  EXPECT_TRUE(f.memory.times(g, f.preconditioner) == mixing(f.w, g));
}

// L-BFGS's order: a product at g_k, the pair to g_{k+1}, a product at g_{k+1}, ... on a
// quadratic (y = A s). Each product applies P once (the newest pair's P y is P g_{k+1} -
// P g_k) and agrees with the two-loop recursion; a product at another point after a pair was
// added (an objective that changed between inner runs) applies P to that pair's y as well.
TEST(LbfgsMemory, InLbfgsOrderEachProductAppliesThePreconditionerOnce) {
  for (const Eigen::Index n : {Eigen::Index{50}, kParallelMinimum + 4097}) {
    Fixture f(n, 0, 4);
    Eigen::VectorXd g = random_vector(n, f.random);
    Eigen::VectorXd d = -f.memory.times(g, f.preconditioner);
    EXPECT_EQ(f.applied(), 1);
    for (int k = 0; k < 7; ++k) {  // past the capacity: storage is reused
      SCOPED_TRACE(k);
      f.take_step(0.3 + 0.1 * k, d, g, 4);
      d = -f.checked_product(g, 1);
    }
    EXPECT_EQ(f.memory.size(), 4);
    // The objective changes: the next product is taken elsewhere than the newest pair's end.
    f.take_step(0.5, d, g, 4);
    (void)f.checked_product(g + random_vector(n, f.random), 2);  // P y of the newest pair, P g
  }
}

// A new inner run whose objective differs from the last one only on a few entries (as the
// seed's correction load, nonzero only on the particles' nodes): after new_objective() the
// newest pair's P y is formed by applying P, and the product is the recursion's on the pairs of
// the old objective.
TEST(LbfgsMemory, NewObjectiveFormsTheNewestPairsZByApplyingThePreconditioner) {
  const Eigen::Index n = kParallelMinimum + 4097;
  Fixture f(n, 0, 4);
  Eigen::VectorXd g = random_vector(n, f.random);
  Eigen::VectorXd d = -f.memory.times(g, f.preconditioner);
  for (int k = 0; k < 3; ++k) {
    f.take_step(1.0, d, g, 4);
    d = -f.memory.times(g, f.preconditioner);
  }
  f.take_step(1.0, d, g, 4);
  Eigen::VectorXd loaded = g;  // another objective's gradient at the same point
  for (const Eigen::Index k : {Eigen::Index{5}, n / 2 + 3, n - 7}) loaded[k] += 1.0;
  f.memory.new_objective();
  (void)f.checked_product(loaded, 2);  // P y of the newest pair, then P g
}

TEST(LbfgsMemory, PairsAddedWithoutProductsAreCompletedByApplyingThePreconditioner) {
  Fixture f(200, 4, 10);
  const Eigen::VectorXd g = random_vector(200, f.random);
  (void)f.memory.times(g, f.preconditioner);
  EXPECT_EQ(f.applied(), 5);  // P y of each of the four pairs, then P g
  const Eigen::VectorXd again = f.memory.times(g, f.preconditioner);
  EXPECT_EQ(f.applied(), 6);  // P g only
  // Another preconditioner: the pairs, which hold P y, are dropped; the product is P g.
  f.memory.preconditioner_changed();
  EXPECT_TRUE(f.memory.empty());
  EXPECT_TRUE(f.memory.times(g, f.preconditioner) == mixing(f.w, g));
}

}  // namespace
}  // namespace mresim::mess::detail
