// The map between node positions and the minimisers' free variables (system/constraints.hpp):
// its passes over the own dofs run on several threads at full size, and must give exactly what
// the definitions give (a serial loop over dof_of()) for any number of threads, with a NaN in a
// gradient reported as NaN by the largest-component measure.

#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <limits>
#include <numeric>
#include <random>
#include <vector>

#include "mresim/mess/system/constraints.hpp"
#include "mresim/mess/system/fixed_order.hpp"

namespace mresim::mess {
namespace {

// Enough nodes that the own dofs span many blocks and the passes run in parallel.
constexpr std::int64_t kNodes = 3 * detail::kParallelMinimum / 2;
constexpr double kLength = 2.5e-7;

Eigen::Matrix3Xd random_positions(std::int64_t nodes, std::mt19937_64& random) {
  std::uniform_real_distribution<double> uniform(-1e-5, 1e-5);
  Eigen::Matrix3Xd x(3, nodes);
  for (Eigen::Index k = 0; k < x.size(); ++k) x.data()[k] = uniform(random);
  return x;
}

// Held coordinates scattered over the nodes, and one rigid group of 200 nodes.
BoundaryConstraints scattered_constraints(const Eigen::Matrix3Xd& x) {
  BoundaryConstraints c = BoundaryConstraints::none(x.cols());
  std::vector<std::int32_t> group(200);
  std::iota(group.begin(), group.end(), 1000);
  for (std::int64_t n = 0; n < x.cols(); ++n) {
    if (n >= 1000 && n < 1200) continue;
    if (n % 7 == 0) c.hold(n, static_cast<int>(n % 3), x(n % 3, n));
    if (n % 11 == 0) c.hold(n, x.col(n));
  }
  c.add_rigid_group(group);
  c.validate(x.cols());
  return c;
}

class DofMapThreads : public ::testing::TestWithParam<int> {};

TEST_P(DofMapThreads, PassesGiveTheDefinitionsExactly) {
  std::mt19937_64 random(7);
  const Eigen::Matrix3Xd reference = random_positions(kNodes, random);
  const BoundaryConstraints c = scattered_constraints(reference);
  const DofMap map(c, reference, kLength);
  ASSERT_GT(map.own_dofs(), 2 * detail::kParallelMinimum);
  ASSERT_EQ(map.groups(), 1);

  const int threads_before = omp_get_max_threads();
  omp_set_num_threads(GetParam());
  const Eigen::Matrix3Xd x = random_positions(kNodes, random);
  const Eigen::Matrix3Xd gradient = random_positions(kNodes, random) * 1e3;
  const Eigen::VectorXd u = map.to_dofs(x);
  Eigen::VectorXd d(map.size());
  for (Eigen::Index k = 0; k < d.size(); ++k) d[k] = std::sin(0.37 * static_cast<double>(k));
  Eigen::Matrix3Xd moved = reference;
  map.to_positions(u, 0.25, d, moved);
  Eigen::VectorXd reduced;
  map.reduce_divided(gradient, 3.0, reduced);
  const double largest = map.max_abs_reduced_divided(gradient, 3.0);
  const Eigen::Matrix3Xd expanded = map.expand(d);
  omp_set_num_threads(threads_before);

  // The definitions, one coordinate at a time.
  const Eigen::Vector3d group_shift = x.col(1000) - reference.col(1000);
  Eigen::VectorXd group_sum = Eigen::VectorXd::Zero(3);
  for (std::int64_t n = 1000; n < 1200; ++n) group_sum += gradient.col(n);
  const Eigen::Index g0 = map.own_dofs();
  double expected_largest = 0.0;
  for (std::int64_t n = 0; n < kNodes; ++n) {
    for (int a = 0; a < 3; ++a) {
      const Eigen::Index k = map.dof_of(n, a);
      const bool grouped = n >= 1000 && n < 1200;
      if (k < 0) {
        EXPECT_EQ(moved(a, n), reference(a, n));
        EXPECT_EQ(expanded(a, n), 0.0);
        continue;
      }
      if (grouped) {
        ASSERT_EQ(k, g0 + a);
        EXPECT_EQ(moved(a, n), reference(a, n) + (u[k] + 0.25 * d[k]) * kLength);
        EXPECT_EQ(expanded(a, n), d[k]);
        continue;
      }
      ASSERT_EQ(map.coordinate_of(k), 3 * n + a);
      EXPECT_EQ(u[k], x(a, n) * (1.0 / kLength));
      EXPECT_EQ(moved(a, n), (u[k] + 0.25 * d[k]) * kLength);
      EXPECT_EQ(reduced[k], gradient(a, n) * kLength / 3.0);
      EXPECT_EQ(expanded(a, n), d[k]);
      expected_largest = std::max(expected_largest, std::abs(reduced[k]));
    }
  }
  for (int a = 0; a < 3; ++a) {
    EXPECT_EQ(u[g0 + a], group_shift[a] * (1.0 / kLength));
    EXPECT_EQ(reduced[g0 + a], group_sum[a] * kLength / 3.0);
    expected_largest = std::max(expected_largest, std::abs(reduced[g0 + a]));
  }
  EXPECT_EQ(largest, expected_largest);
}

INSTANTIATE_TEST_SUITE_P(OneToEight, DofMapThreads, ::testing::Values(1, 2, 3, 8));

TEST(DofMap, LargestComponentIsNanWhereverTheGradientHasOne) {
  std::mt19937_64 random(11);
  const Eigen::Matrix3Xd reference = random_positions(kNodes, random);
  const BoundaryConstraints c = scattered_constraints(reference);
  const DofMap map(c, reference, kLength);
  const Eigen::Matrix3Xd gradient = random_positions(kNodes, random);
  // A free coordinate early and late in the own dofs, and one of the group's nodes.
  for (const std::int64_t node : {std::int64_t{1}, kNodes - 3, std::int64_t{1100}}) {
    Eigen::Matrix3Xd g = gradient;
    g(1, node) = std::numeric_limits<double>::quiet_NaN();
    ASSERT_GE(map.dof_of(node, 1), 0);
    EXPECT_TRUE(std::isnan(map.max_abs_reduced_divided(g, 1.0))) << "node " << node;
  }
}

}  // namespace
}  // namespace mresim::mess
