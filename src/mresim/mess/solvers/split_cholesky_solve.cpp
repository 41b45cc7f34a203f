#include "mresim/mess/solvers/split_cholesky_solve.hpp"

#include <algorithm>
#include <cstddef>
#include <functional>
#include <queue>
#include <utility>

namespace mresim::mess::detail {

namespace {

// Below this many entries of L one thread solves faster than two share the work.
constexpr long kParallelEntries = 100000;
// After no subtree outweighs the others together, this many further expansions are tried for a
// better balance; the best split found is kept.
constexpr int kRefinements = 32;

struct EliminationTree {
  std::vector<int> parent;       // -1 at a root
  std::vector<long> entries;     // entries of L in each column
  std::vector<long> subtree;     // entries of L in each column's subtree
  std::vector<int> child_begin;  // children of j: child[child_begin[j] .. child_begin[j + 1]]
  std::vector<int> child;
};

EliminationTree elimination_tree(const Eigen::SparseMatrix<float>& lower) {
  const auto n = static_cast<int>(lower.cols());
  const int* start = lower.outerIndexPtr();
  const int* row = lower.innerIndexPtr();
  EliminationTree t;
  t.parent.assign(static_cast<std::size_t>(n), -1);
  t.entries.assign(static_cast<std::size_t>(n), 0);
  std::vector<int> children(static_cast<std::size_t>(n) + 1, 0);
  for (int j = 0; j < n; ++j) {
    const auto jj = static_cast<std::size_t>(j);
    int parent = -1;
    for (int e = start[j] + 1; e < start[j + 1]; ++e) {
      parent = parent < 0 ? row[e] : std::min(parent, row[e]);
    }
    t.parent[jj] = parent;
    t.entries[jj] = start[j + 1] - start[j];
    if (parent >= 0) ++children[static_cast<std::size_t>(parent)];
  }
  // A parent comes after its children (L is lower triangular), so one ascending pass sums the
  // subtrees.
  t.subtree = t.entries;
  for (int j = 0; j < n; ++j) {
    const int p = t.parent[static_cast<std::size_t>(j)];
    if (p >= 0) t.subtree[static_cast<std::size_t>(p)] += t.subtree[static_cast<std::size_t>(j)];
  }
  t.child_begin.assign(static_cast<std::size_t>(n) + 1, 0);
  for (int j = 0; j < n; ++j) {
    t.child_begin[static_cast<std::size_t>(j) + 1] =
        t.child_begin[static_cast<std::size_t>(j)] + children[static_cast<std::size_t>(j)];
  }
  t.child.assign(static_cast<std::size_t>(t.child_begin.back()), 0);
  std::vector<int> fill(t.child_begin.begin(), t.child_begin.end() - 1);
  for (int j = 0; j < n; ++j) {
    const int p = t.parent[static_cast<std::size_t>(j)];
    if (p >= 0) t.child[static_cast<std::size_t>(fill[static_cast<std::size_t>(p)]++)] = j;
  }
  return t;
}

// Subtree roots below the trunk: the trunk grows by taking the heaviest root (ties: the lowest
// column) into it and its children in its place. Deterministic: it depends on the tree alone.
class Frontier {
 public:
  explicit Frontier(const EliminationTree& tree) : tree_(tree), heap_(Heavier{&tree}) {
    for (std::size_t j = 0; j < tree.parent.size(); ++j) {
      if (tree.parent[j] < 0) push(static_cast<int>(j));
    }
  }
  [[nodiscard]] bool empty() const { return heap_.empty(); }
  [[nodiscard]] long heaviest() const {
    return heap_.empty() ? 0 : tree_.subtree[static_cast<std::size_t>(heap_.top())];
  }
  [[nodiscard]] long total() const { return total_; }
  [[nodiscard]] long trunk() const { return trunk_; }
  // Moves the heaviest root into the trunk; returns it.
  int expand() {
    const int j = heap_.top();
    heap_.pop();
    const auto jj = static_cast<std::size_t>(j);
    total_ -= tree_.subtree[jj];
    trunk_ += tree_.entries[jj];
    for (int c = tree_.child_begin[jj]; c < tree_.child_begin[jj + 1]; ++c) {
      push(tree_.child[static_cast<std::size_t>(c)]);
    }
    return j;
  }
  // The roots dealt to two branches, heaviest first, each to the lighter branch (longest
  // processing time first); their loads.
  std::pair<std::array<std::vector<int>, 2>, std::array<long, 2>> deal() const {
    std::vector<int> roots;
    auto copy = heap_;
    while (!copy.empty()) {
      roots.push_back(copy.top());
      copy.pop();
    }
    std::array<std::vector<int>, 2> branch;
    std::array<long, 2> load{0, 0};
    for (const int r : roots) {
      const std::size_t b = load[1] < load[0] ? 1 : 0;
      branch[b].push_back(r);
      load[b] += tree_.subtree[static_cast<std::size_t>(r)];
    }
    return {branch, load};
  }

 private:
  struct Heavier {
    const EliminationTree* tree;
    bool operator()(int a, int b) const {  // true: a comes after b
      const long wa = tree->subtree[static_cast<std::size_t>(a)];
      const long wb = tree->subtree[static_cast<std::size_t>(b)];
      return wa != wb ? wa < wb : a > b;
    }
  };
  void push(int j) {
    heap_.push(j);
    total_ += tree_.subtree[static_cast<std::size_t>(j)];
  }
  const EliminationTree& tree_;
  std::priority_queue<int, std::vector<int>, Heavier> heap_;
  long total_ = 0;
  long trunk_ = 0;
};

// How many expansions give the best split: the trunk's entries plus the heavier branch's.
int best_expansions(const EliminationTree& tree) {
  Frontier frontier(tree);
  int done = 0;
  while (!frontier.empty() && 2 * frontier.heaviest() > frontier.total()) {
    (void)frontier.expand();
    ++done;
  }
  const auto cost = [](const Frontier& f) {
    const auto load = f.deal().second;
    return f.trunk() + std::max(load[0], load[1]);
  };
  int best = done;
  long best_cost = cost(frontier);
  for (int k = 1; k <= kRefinements && !frontier.empty(); ++k) {
    (void)frontier.expand();
    const long c = cost(frontier);
    if (c < best_cost) {
      best_cost = c;
      best = done + k;
    }
  }
  return best;
}

// Every column of the subtree under `root`, appended to `columns`.
void append_subtree(const EliminationTree& tree, int root, std::vector<int>& columns) {
  std::vector<int> stack{root};
  while (!stack.empty()) {
    const int j = stack.back();
    stack.pop_back();
    columns.push_back(j);
    const auto jj = static_cast<std::size_t>(j);
    for (int c = tree.child_begin[jj]; c < tree.child_begin[jj + 1]; ++c) {
      stack.push_back(tree.child[static_cast<std::size_t>(c)]);
    }
  }
}

}  // namespace

SplitCholeskySolve::SplitCholeskySolve(const Eigen::SparseMatrix<float>& lower) {
  const auto n = static_cast<int>(lower.cols());
  trunk_slot_.assign(static_cast<std::size_t>(n), -1);
  const EliminationTree tree = elimination_tree(lower);
  const long entries = lower.nonZeros();
  // Small factors stay whole in the trunk: one thread solves them.
  const int expansions = entries < kParallelEntries ? n : best_expansions(tree);
  Frontier frontier(tree);
  std::vector<char> in_trunk(static_cast<std::size_t>(n), 0);
  for (int k = 0; k < expansions && !frontier.empty(); ++k) {
    in_trunk[static_cast<std::size_t>(frontier.expand())] = 1;
  }
  const auto [roots, load] = frontier.deal();
  branch_entries_ = load;
  trunk_entries_ = frontier.trunk();
  for (std::size_t b = 0; b < 2; ++b) {
    for (const int r : roots[b]) append_subtree(tree, r, branch_columns_[b]);
    std::sort(branch_columns_[b].begin(), branch_columns_[b].end());
  }
  for (int j = 0; j < n; ++j) {
    if (in_trunk[static_cast<std::size_t>(j)] == 0) continue;
    trunk_slot_[static_cast<std::size_t>(j)] = static_cast<int>(trunk_columns_.size());
    trunk_columns_.push_back(j);
  }
}

void SplitCholeskySolve::solve(const Eigen::SparseMatrix<float>& lower, Eigen::VectorXd& y) const {
  const int* start = lower.outerIndexPtr();
  const int* row = lower.innerIndexPtr();
  const float* value = lower.valuePtr();
  double* const x = y.data();
  const auto trunk = static_cast<Eigen::Index>(trunk_columns_.size());
  // Forward, L y = b: each branch's columns, their terms for trunk rows in the branch's buffer.
  std::array<Eigen::VectorXd, 2> buffer{Eigen::VectorXd::Zero(trunk), Eigen::VectorXd::Zero(trunk)};
  const bool both = branch_entries_[0] + branch_entries_[1] >= kParallelEntries;
#pragma omp parallel for schedule(static, 1) if (both)
  for (int b = 0; b < 2; ++b) {
    double* const to_trunk = buffer[static_cast<std::size_t>(b)].data();
    for (const int j : branch_columns_[static_cast<std::size_t>(b)]) {
      const double xj = x[j] /= static_cast<double>(value[start[j]]);
      for (int e = start[j] + 1; e < start[j + 1]; ++e) {
        const int s = trunk_slot_[static_cast<std::size_t>(row[e])];
        if (s < 0) {
          x[row[e]] -= static_cast<double>(value[e]) * xj;
        } else {
          to_trunk[s] -= static_cast<double>(value[e]) * xj;
        }
      }
    }
  }
  for (Eigen::Index s = 0; s < trunk; ++s) {
    double& t = x[trunk_columns_[static_cast<std::size_t>(s)]];
    t = (t + buffer[0][s]) + buffer[1][s];
  }
  for (const int j : trunk_columns_) {  // the trunk's rows take terms from trunk columns only
    const double xj = x[j] /= static_cast<double>(value[start[j]]);
    for (int e = start[j] + 1; e < start[j + 1]; ++e) {
      x[row[e]] -= static_cast<double>(value[e]) * xj;
    }
  }
  // Backward, L^T x = y: each column gathers from the rows below it, which are its ancestors.
  const auto gather = [&](int j) {
    double sum = x[j];
    for (int e = start[j] + 1; e < start[j + 1]; ++e) {
      sum -= static_cast<double>(value[e]) * x[row[e]];
    }
    x[j] = sum / static_cast<double>(value[start[j]]);
  };
  for (std::size_t k = trunk_columns_.size(); k-- > 0;) gather(trunk_columns_[k]);
#pragma omp parallel for schedule(static, 1) if (both)
  for (int b = 0; b < 2; ++b) {
    const std::vector<int>& columns = branch_columns_[static_cast<std::size_t>(b)];
    for (std::size_t k = columns.size(); k-- > 0;) gather(columns[k]);
  }
}

void serial_cholesky_solve(const Eigen::SparseMatrix<float>& lower, Eigen::VectorXd& y) {
  const int* start = lower.outerIndexPtr();
  const int* row = lower.innerIndexPtr();
  const float* value = lower.valuePtr();
  const auto n = static_cast<int>(lower.cols());
  for (int j = 0; j < n; ++j) {
    y[j] /= static_cast<double>(value[start[j]]);
    for (int e = start[j] + 1; e < start[j + 1]; ++e) {
      y[row[e]] -= static_cast<double>(value[e]) * y[j];
    }
  }
  for (int j = n - 1; j >= 0; --j) {
    double sum = y[j];
    for (int e = start[j] + 1; e < start[j + 1]; ++e) {
      sum -= static_cast<double>(value[e]) * y[row[e]];
    }
    y[j] = sum / static_cast<double>(value[start[j]]);
  }
}

}  // namespace mresim::mess::detail
