#pragma once

// The two triangular solves of a sparse Cholesky factor, L L^T x = b, on two threads, bitwise the
// same on any number of threads. The gap blocks of the minimisers' preconditioner
// (contact_gap_blocks.hpp) apply their factor once per L-BFGS iteration; serial, those solves
// took about a quarter of an iteration in contact at full size while the second core waited
// (docs/performance.md, "The gap's solves on both cores").
//
// How. In column j of L every off-diagonal row i is an ancestor of j in the factor's
// elimination tree (parent(j) = the smallest such i; Liu, "The role of elimination trees in
// sparse factorization", SIAM J. Matrix Anal. Appl. 11, 1990). So the columns of two disjoint
// subtrees touch each other's rows in neither solve: the tree is split into a trunk (a set of
// columns closed towards the roots) and subtrees below it, and the subtrees are dealt to two
// branches of about equal work (entries of L), each solved by one thread.
//   forward, L y = b (column by column, each column scattering into the rows below it): each
//     branch solves its own columns; what they subtract from trunk rows is summed in a buffer of
//     the branch's own; the trunk rows then take b + buffer 0 + buffer 1 (in that order), and
//     the trunk's columns are solved in turn;
//   backward, L^T x = y (each column gathering from the rows below it): the trunk's columns
//     first, then each branch's, both branches at once.
// The split depends on the factor alone, and each branch's sums come in the same order whoever
// runs it, so the result is the same on one thread as on two. Against a plain serial solve the
// forward solve's trunk rows differ by rounding (their terms are summed in another order).
//
// Memory: three ints per column of L (its branch's column lists and its trunk slot), and while a
// forward solve runs two buffers of trunk rows.

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <array>
#include <vector>

namespace mresim::mess::detail {

class SplitCholeskySolve {
 public:
  SplitCholeskySolve() = default;
  // `lower`: the factor L, column-major, each column's diagonal entry first (as Eigen's
  // SimplicialLLT keeps it). It is read again by solve(), so it must outlive this object.
  explicit SplitCholeskySolve(const Eigen::SparseMatrix<float>& lower);

  // y <- (L L^T)^-1 y, in double precision.
  void solve(const Eigen::SparseMatrix<float>& lower, Eigen::VectorXd& y) const;

  // The split, for tests and the record: entries of L in each branch and in the trunk.
  [[nodiscard]] const std::array<long, 2>& branch_entries() const { return branch_entries_; }
  [[nodiscard]] long trunk_entries() const { return trunk_entries_; }

 private:
  std::array<std::vector<int>, 2> branch_columns_;  // ascending
  std::vector<int> trunk_columns_;                  // ascending
  std::vector<int> trunk_slot_;                     // column -> its place in trunk_columns_, or -1
  std::array<long, 2> branch_entries_{};
  long trunk_entries_ = 0;
};

// The plain forward and back substitution through `lower` (column by column, one thread): y <-
// (L L^T)^-1 y. The reference the split is measured and tested against.
void serial_cholesky_solve(const Eigen::SparseMatrix<float>& lower, Eigen::VectorXd& y);

}  // namespace mresim::mess::detail
