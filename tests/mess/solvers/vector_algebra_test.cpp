// The solvers' parallel vector algebra (vector_algebra.hpp): the same values as the serial
// formulas (to rounding), and bitwise the same results for any number of threads.

#include "mresim/mess/solvers/vector_algebra.hpp"

#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <random>

namespace mresim::mess::detail {
namespace {

Eigen::VectorXd normal_random_vector(Eigen::Index n, unsigned seed) {
  std::mt19937_64 random(seed);
  std::normal_distribution<double> normal;
  Eigen::VectorXd v(n);
  for (Eigen::Index k = 0; k < n; ++k) v[k] = normal(random);
  return v;
}

// Sizes below one block, across the parallel threshold and with a partial last block.
const Eigen::Index kSizes[] = {
    1, 7, kSumBlock, kSumBlock + 3, kParallelMinimum + 12345, 9 * kSumBlock - 1};

TEST(VectorAlgebra, AgreesWithTheSerialFormulas) {
  for (const Eigen::Index n : kSizes) {
    const Eigen::VectorXd a = normal_random_vector(n, 1);
    const Eigen::VectorXd b = normal_random_vector(n, 2);
    const Eigen::VectorXd c = normal_random_vector(n, 3);
    const double scale = a.cwiseAbs().dot(b.cwiseAbs());
    EXPECT_NEAR(parallel_dot(a, b), a.dot(b), 1e-13 * scale) << n;
    EXPECT_EQ(parallel_max_abs(a), a.cwiseAbs().maxCoeff()) << n;

    Eigen::VectorXd y = b;
    parallel_axpy(0.75, a, y);
    EXPECT_TRUE(y.isApprox(b + 0.75 * a, 1e-15)) << n;

    y = b;
    parallel_scale_add(-0.5, a, y);
    EXPECT_TRUE(y.isApprox(a - 0.5 * b, 1e-15)) << n;

    y = b;
    const double fused = parallel_axpy_dot(-1.25, a, y, c);
    const Eigen::VectorXd expected = b - 1.25 * a;
    EXPECT_TRUE(y.isApprox(expected, 1e-15)) << n;
    EXPECT_NEAR(fused, c.dot(expected), 1e-13 * c.cwiseAbs().dot(expected.cwiseAbs())) << n;
  }
}

TEST(VectorAlgebra, ResultsAreBitwiseIndependentOfTheThreadCount) {
  const Eigen::Index n = 5 * kParallelMinimum + 17;
  const Eigen::VectorXd a = normal_random_vector(n, 4);
  const Eigen::VectorXd b = normal_random_vector(n, 5);
  const int saved = omp_get_max_threads();
  double dots[2] = {0.0, 0.0};
  double fused[2] = {0.0, 0.0};
  Eigen::VectorXd updated[2];
  for (const int threads : {1, 2}) {
    omp_set_num_threads(threads);
    dots[threads - 1] = parallel_dot(a, b);
    updated[threads - 1] = b;
    fused[threads - 1] = parallel_axpy_dot(0.3, a, updated[threads - 1], a);
  }
  omp_set_num_threads(saved);
  EXPECT_EQ(dots[0], dots[1]);
  EXPECT_EQ(fused[0], fused[1]);
  EXPECT_TRUE(updated[0] == updated[1]);
}

TEST(VectorAlgebra, EmptyVectorsGiveZero) {
  const Eigen::VectorXd empty;
  EXPECT_EQ(parallel_dot(empty, empty), 0.0);
  EXPECT_EQ(parallel_max_abs(empty), 0.0);
}

}  // namespace
}  // namespace mresim::mess::detail
