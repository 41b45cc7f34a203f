#include "mresim/mess/solvers/lbfgs_memory.hpp"

#include <algorithm>
#include <utility>
#include <vector>

#include "mresim/mess/solvers/vector_algebra.hpp"

namespace mresim::mess::detail {

void LbfgsMemory::clear() {
  S_.clear();
  Y_.clear();
  rho_.clear();
  scale_known_ = false;
}

void LbfgsMemory::set_split(std::shared_ptr<const BlockSplit> split) {
  clear();
  split_ = std::move(split);
}

Eigen::Index LbfgsMemory::stored_entries() const {
  Eigen::Index total = 0;
  for (const auto& s : S_) total += s.size();
  for (const auto& y : Y_) total += y.size();
  return total;
}

void LbfgsMemory::drop_oldest() {
  S_.pop_front();
  Y_.pop_front();
  rho_.pop_front();
}

OwnedBlocks LbfgsMemory::owned(Eigen::Index n) const {
  return split_ != nullptr ? split_->owned(n) : all_blocks(n);
}

template <class Block>
double LbfgsMemory::sum_owned(Eigen::Index n, Block&& block) const {
  if (split_ == nullptr) return sum_over_blocks(n, std::forward<Block>(block));
  const OwnedBlocks o = split_->owned(n);
  std::vector<double> block_sums(static_cast<std::size_t>(all_blocks(n).last_block), 0.0);
#pragma omp parallel for schedule(static) if (o.length() >= kParallelMinimum)
  for (Eigen::Index b = o.first_block; b < o.last_block; ++b) {
    const Eigen::Index begin = b * kSumBlock;
    block_sums[static_cast<std::size_t>(b)] = block(begin, std::min(kSumBlock, n - begin));
  }
  split_->share_block_sums(block_sums, n);
  if (block_sums.size() == 1) return block_sums.front();  // as sum_over_blocks
  double total = 0.0;
  for (const double s : block_sums) total += s;
  return total;
}

void LbfgsMemory::add(double alpha, const Eigen::VectorXd& d, const Eigen::VectorXd& g_new,
                      const Eigen::VectorXd& g_old, int capacity) {
  const Eigen::Index n = d.size();
  const auto s_of = [&](Eigen::Index begin, Eigen::Index length) {
    return alpha * d.segment(begin, length);
  };
  const auto y_of = [&](Eigen::Index begin, Eigen::Index length) {
    return g_new.segment(begin, length) - g_old.segment(begin, length);
  };
  const double sy =
      sum_owned(n, [&](Eigen::Index b, Eigen::Index l) { return s_of(b, l).dot(y_of(b, l)); });
  const double yy =
      sum_owned(n, [&](Eigen::Index b, Eigen::Index l) { return y_of(b, l).squaredNorm(); });
  if (!(sy > 1e-12 * yy && sy > 0.0)) return;
  const OwnedBlocks o = owned(n);
  if (!S_.empty() && S_.front().size() != o.length()) clear();  // another problem size
  Eigen::VectorXd s_store;
  Eigen::VectorXd y_store;
  if (size() >= capacity && !S_.empty()) {  // reuse the oldest pair's storage
    s_store = std::move(S_.front());
    y_store = std::move(Y_.front());
    drop_oldest();
  }
  offset_ = o.begin;
  s_store.resize(o.length());
  y_store.resize(o.length());
  (void)sum_over_blocks(o.length(), [&](Eigen::Index b, Eigen::Index l) {
    s_store.segment(b, l) = s_of(o.begin + b, l);
    y_store.segment(b, l) = y_of(o.begin + b, l);
    return 0.0;
  });
  S_.push_back(std::move(s_store));
  Y_.push_back(std::move(y_store));
  rho_.push_back(1.0 / sy);
  while (size() > capacity) drop_oldest();  // a smaller capacity than before
  scale_known_ = false;
}

Eigen::VectorXd LbfgsMemory::times(const Eigen::VectorXd& g, const Preconditioner& P) {
  const Eigen::Index n = g.size();
  const OwnedBlocks o = owned(n);
  Eigen::VectorXd q;
  parallel_copy(g, q);
  const int m = size();
  const auto idx = [](int k) { return static_cast<std::size_t>(k); };
  const auto dot = [&](const Eigen::VectorXd& stored, const Eigen::VectorXd& whole) {
    return sum_owned(n, [&](Eigen::Index b, Eigen::Index l) {
      return at(stored, b, l).dot(whole.segment(b, l));
    });
  };
  // q += alpha x (x stored) over this process's blocks; then, when `next` is given, next . q.
  const auto update = [&](double alpha, const Eigen::VectorXd& x, const Eigen::VectorXd* next) {
    if (next == nullptr) {
      (void)sum_over_blocks(o.length(), [&](Eigen::Index b, Eigen::Index l) {
        q.segment(o.begin + b, l) += alpha * x.segment(b, l);
        return 0.0;
      });
      return 0.0;
    }
    return sum_owned(n, [&](Eigen::Index b, Eigen::Index l) {
      auto qb = q.segment(b, l);
      qb += alpha * at(x, b, l);
      return at(*next, b, l).dot(qb);
    });
  };
  std::vector<double> a(idx(m));
  // Newest to oldest: a_k = rho_k s_k.q, q -= a_k y_k; each update also forms s_{k-1}.q.
  double sq = m > 0 ? dot(S_[idx(m - 1)], q) : 0.0;
  for (int k = m - 1; k >= 0; --k) {
    a[idx(k)] = rho_[idx(k)] * sq;
    sq = update(-a[idx(k)], Y_[idx(k)], k > 0 ? &S_[idx(k - 1)] : nullptr);
  }
  if (m > 0) {
    if (split_ != nullptr) split_->share_entries(q);  // P needs the whole vector
    if (!scale_known_) {
      Eigen::VectorXd y_whole;
      if (split_ != nullptr) {
        y_whole = Eigen::VectorXd::Zero(n);
        y_whole.segment(o.begin, o.length()) = Y_.back();
        split_->share_entries(y_whole);
      }
      const Eigen::VectorXd& y = split_ != nullptr ? y_whole : Y_.back();
      scale_ = dot(S_.back(), y) / dot(Y_.back(), P(y));
      scale_known_ = true;
    }
    q = P(q);
    parallel_scale(scale_, q);
  } else {
    q = P(q);
  }
  // Oldest to newest: b_k = rho_k y_k.q, q += (a_k - b_k) s_k; each update also forms
  // y_{k+1}.q.
  double yq = m > 0 ? dot(Y_[0], q) : 0.0;
  for (int k = 0; k < m; ++k) {
    const double b = rho_[idx(k)] * yq;
    yq = update(a[idx(k)] - b, S_[idx(k)], k + 1 < m ? &Y_[idx(k + 1)] : nullptr);
  }
  if (m > 0 && split_ != nullptr) split_->share_entries(q);
  return q;
}

}  // namespace mresim::mess::detail
