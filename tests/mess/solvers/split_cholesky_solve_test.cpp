// The sparse Cholesky factor's solves split over its elimination tree
// (solvers/split_cholesky_solve.hpp): they solve L L^T x = b as the plain forward and back
// substitution does (to rounding), bitwise the same on one thread and on two, and the split
// accounts for every entry of L: two branches of about equal work and a trunk.

#include "mresim/mess/solvers/split_cholesky_solve.hpp"

#include <gtest/gtest.h>
#include <omp.h>

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <cstdlib>
#include <vector>

#include "../support/multilevel_test_support.hpp"

namespace {

using Factor = Eigen::SimplicialLLT<Eigen::SparseMatrix<float>>;
using mresim::mess::detail::serial_cholesky_solve;
using mresim::mess::detail::SplitCholeskySolve;
using mresim::mess::testing::uniform_random_vector;

// A 27-point stencil on an n x n x n grid (each node coupled to its 26 neighbours with -1, its
// diagonal 27): symmetric positive definite, and its factor fills in as the gap's block does.
// `blocks` copies of it side by side, uncoupled.
Eigen::SparseMatrix<float> grid_matrix(int n, int blocks = 1) {
  const int size = n * n * n;
  std::vector<Eigen::Triplet<float>> entries;
  for (int block = 0; block < blocks; ++block) {
    const int offset = block * size;
    for (int z = 0; z < n; ++z) {
      for (int y = 0; y < n; ++y) {
        for (int x = 0; x < n; ++x) {
          const int i = x + n * (y + n * z);
          entries.emplace_back(offset + i, offset + i, 27.0F);
          for (int dz = -1; dz <= 1; ++dz) {
            for (int dy = -1; dy <= 1; ++dy) {
              for (int dx = -1; dx <= 1; ++dx) {
                const int X = x + dx;
                const int Y = y + dy;
                const int Z = z + dz;
                if ((dx == 0 && dy == 0 && dz == 0) || X < 0 || Y < 0 || Z < 0 || X >= n ||
                    Y >= n || Z >= n) {
                  continue;
                }
                entries.emplace_back(offset + i, offset + X + n * (Y + n * Z), -1.0F);
              }
            }
          }
        }
      }
    }
  }
  Eigen::SparseMatrix<float> a(blocks * size, blocks * size);
  a.setFromTriplets(entries.begin(), entries.end());
  return a;
}

// Solves with `threads` threads, the number restored afterwards.
Eigen::VectorXd solve_with(const SplitCholeskySolve& split, const Eigen::SparseMatrix<float>& lower,
                           const Eigen::VectorXd& b, int threads) {
  const int before = omp_get_max_threads();
  omp_set_num_threads(threads);
  Eigen::VectorXd y = b;
  split.solve(lower, y);
  omp_set_num_threads(before);
  return y;
}

TEST(SplitCholeskySolve, SolvesAsTheSubstitutionDoesAndSplitsEveryEntry) {
  const Eigen::SparseMatrix<float> a = grid_matrix(14);
  const Factor factor(a);
  ASSERT_EQ(factor.info(), Eigen::Success);
  const Eigen::SparseMatrix<float>& lower = factor.matrixL().nestedExpression();
  ASSERT_GT(lower.nonZeros(), 200000);  // large enough to be split
  const SplitCholeskySolve split(lower);
  const auto& branch = split.branch_entries();
  EXPECT_EQ(branch[0] + branch[1] + split.trunk_entries(), lower.nonZeros());
  EXPECT_GT(branch[0], 0);
  EXPECT_GT(branch[1], 0);
  // The trunk holds the top separators' dense columns; the branches carry most of the work, in
  // about equal parts.
  EXPECT_LT(split.trunk_entries(), lower.nonZeros() / 2);
  EXPECT_LT(std::abs(branch[0] - branch[1]), (branch[0] + branch[1]) / 5);

  const Eigen::VectorXd b = uniform_random_vector(a.rows(), 7);
  Eigen::VectorXd reference = factor.permutationP() * b;
  serial_cholesky_solve(lower, reference);
  const Eigen::VectorXd permuted = factor.permutationP() * b;
  const Eigen::VectorXd one = solve_with(split, lower, permuted, 1);
  const Eigen::VectorXd two = solve_with(split, lower, permuted, 2);
  EXPECT_TRUE(one == two) << "the result depends on the number of threads";
  EXPECT_LT((one - reference).cwiseAbs().maxCoeff(), 1e-12 * reference.cwiseAbs().maxCoeff());
  // And it solves A x = b to the single-precision factor's accuracy.
  const Eigen::VectorXd x = factor.permutationP().transpose() * one;
  const Eigen::VectorXd residual = a.cast<double>() * x - b;
  EXPECT_LT(residual.norm(), 1e-4 * b.norm());
}

TEST(SplitCholeskySolve, TwoUncoupledBlocksAreTwoBranchesWithoutATrunk) {
  const Eigen::SparseMatrix<float> a = grid_matrix(11, 2);
  const Factor factor(a);
  ASSERT_EQ(factor.info(), Eigen::Success);
  const Eigen::SparseMatrix<float>& lower = factor.matrixL().nestedExpression();
  const SplitCholeskySolve split(lower);
  EXPECT_EQ(split.trunk_entries(), 0);
  const auto& branch = split.branch_entries();
  EXPECT_LT(std::abs(branch[0] - branch[1]), (branch[0] + branch[1]) / 10);
  const Eigen::VectorXd b = uniform_random_vector(a.rows(), 8);
  Eigen::VectorXd reference = b;
  serial_cholesky_solve(lower, reference);
  // Without a trunk no sum changes its order: bitwise the plain substitution.
  EXPECT_TRUE(solve_with(split, lower, b, 2) == reference);
  EXPECT_TRUE(solve_with(split, lower, b, 1) == reference);
}

TEST(SplitCholeskySolve, ASmallFactorStaysWholeInTheTrunk) {
  const Eigen::SparseMatrix<float> a = grid_matrix(5);
  const Factor factor(a);
  ASSERT_EQ(factor.info(), Eigen::Success);
  const Eigen::SparseMatrix<float>& lower = factor.matrixL().nestedExpression();
  ASSERT_LT(lower.nonZeros(), 100000);
  const SplitCholeskySolve split(lower);
  EXPECT_EQ(split.trunk_entries(), lower.nonZeros());
  EXPECT_EQ(split.branch_entries()[0] + split.branch_entries()[1], 0);
  const Eigen::VectorXd b = uniform_random_vector(a.rows(), 9);
  Eigen::VectorXd reference = b;
  serial_cholesky_solve(lower, reference);
  EXPECT_TRUE(solve_with(split, lower, b, 2) == reference);
}

}  // namespace
