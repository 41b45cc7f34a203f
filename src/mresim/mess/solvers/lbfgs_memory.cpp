#include "mresim/mess/solvers/lbfgs_memory.hpp"

#include <algorithm>
#include <array>
#include <type_traits>
#include <utility>
#include <vector>

#include "mresim/mess/solvers/vector_algebra.hpp"

namespace mresim::mess::detail {

namespace {

// The recursion's two kernels on one block of a stored vector x (entries [xb, xb + l)) and a
// whole one w (entries [wb, wb + l)). In double precision Eigen's (the bits the recursion has
// always had); in single precision explicit loops, since Eigen's dot of a cast expression is
// not vectorised (3x slower than the double dot, measured): four partial sums in a fixed order
// (the same for every thread count), and the update vectorised by the compiler.
double stored_dot(const Eigen::VectorXd& x, Eigen::Index xb, const Eigen::VectorXd& w,
                  Eigen::Index wb, Eigen::Index l) {
  return x.segment(xb, l).dot(w.segment(wb, l));
}

double stored_dot(const Eigen::VectorXf& x, Eigen::Index xb, const Eigen::VectorXd& w,
                  Eigen::Index wb, Eigen::Index l) {
  const float* a = x.data() + xb;
  const double* b = w.data() + wb;
  std::array<double, 4> sum{0.0, 0.0, 0.0, 0.0};
  Eigen::Index i = 0;
  for (; i + 4 <= l; i += 4) {
    for (std::size_t k = 0; k < 4; ++k) {
      sum[k] += static_cast<double>(a[i + static_cast<Eigen::Index>(k)]) *
                b[i + static_cast<Eigen::Index>(k)];
    }
  }
  for (; i < l; ++i) sum[0] += static_cast<double>(a[i]) * b[i];
  return (sum[0] + sum[1]) + (sum[2] + sum[3]);
}

// w[wb, wb + l) += alpha x[xb, xb + l)
void stored_axpy(double alpha, const Eigen::VectorXd& x, Eigen::Index xb, Eigen::VectorXd& w,
                 Eigen::Index wb, Eigen::Index l) {
  w.segment(wb, l) += alpha * x.segment(xb, l);
}

void stored_axpy(double alpha, const Eigen::VectorXf& x, Eigen::Index xb, Eigen::VectorXd& w,
                 Eigen::Index wb, Eigen::Index l) {
  const float* a = x.data() + xb;
  double* b = w.data() + wb;
#pragma omp simd
  for (Eigen::Index i = 0; i < l; ++i) b[i] += alpha * static_cast<double>(a[i]);
}

}  // namespace

void LbfgsMemory::clear() {
  S_.clear();
  Y_.clear();
  Sf_.clear();
  Yf_.clear();
  rho_.clear();
  scale_known_ = false;
}

void LbfgsMemory::set_precision(LbfgsPrecision precision) {
  if (precision != precision_) clear();
  precision_ = precision;
}

void LbfgsMemory::set_split(std::shared_ptr<const BlockSplit> split) {
  clear();
  split_ = std::move(split);
}

Eigen::Index LbfgsMemory::stored_entries() const {
  Eigen::Index total = 0;
  for (const auto* pairs : {&S_, &Y_}) {
    for (const auto& v : *pairs) total += v.size();
  }
  for (const auto* pairs : {&Sf_, &Yf_}) {
    for (const auto& v : *pairs) total += v.size();
  }
  return total;
}

Eigen::Index LbfgsMemory::stored_bytes() const {
  const auto bytes = static_cast<Eigen::Index>(
      precision_ == LbfgsPrecision::single_precision ? sizeof(float) : sizeof(double));
  return bytes * stored_entries();
}

void LbfgsMemory::drop_oldest() {
  if (precision_ == LbfgsPrecision::single_precision) {
    Sf_.pop_front();
    Yf_.pop_front();
  } else {
    S_.pop_front();
    Y_.pop_front();
  }
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
  if (precision_ == LbfgsPrecision::single_precision) {
    add_to(Sf_, Yf_, alpha, d, g_new, g_old, capacity);
  } else {
    add_to(S_, Y_, alpha, d, g_new, g_old, capacity);
  }
}

template <class Stored>
void LbfgsMemory::add_to(std::deque<Stored>& S, std::deque<Stored>& Y, double alpha,
                         const Eigen::VectorXd& d, const Eigen::VectorXd& g_new,
                         const Eigen::VectorXd& g_old, int capacity) {
  using Scalar = typename Stored::Scalar;
  const Eigen::Index n = d.size();
  // s and y as they will be stored (a no-op cast in double precision): s.y and y.y are those
  // of the stored pair, so the recursion is the L-BFGS operator of what it holds.
  const auto s_of = [&](Eigen::Index begin, Eigen::Index length) {
    return (alpha * d.segment(begin, length)).template cast<Scalar>().template cast<double>();
  };
  const auto y_of = [&](Eigen::Index begin, Eigen::Index length) {
    return (g_new.segment(begin, length) - g_old.segment(begin, length))
        .template cast<Scalar>()
        .template cast<double>();
  };
  const double sy =
      sum_owned(n, [&](Eigen::Index b, Eigen::Index l) { return s_of(b, l).dot(y_of(b, l)); });
  const double yy =
      sum_owned(n, [&](Eigen::Index b, Eigen::Index l) { return y_of(b, l).squaredNorm(); });
  if (!(sy > 1e-12 * yy && sy > 0.0)) return;
  const OwnedBlocks o = owned(n);
  if (!S.empty() && S.front().size() != o.length()) clear();  // another problem size
  Stored s_store;
  Stored y_store;
  if (size() >= capacity && !S.empty()) {  // reuse the oldest pair's storage
    s_store = std::move(S.front());
    y_store = std::move(Y.front());
    drop_oldest();
  }
  offset_ = o.begin;
  s_store.resize(o.length());
  y_store.resize(o.length());
  (void)sum_over_blocks(o.length(), [&](Eigen::Index b, Eigen::Index l) {
    s_store.segment(b, l) = s_of(o.begin + b, l).template cast<Scalar>();
    y_store.segment(b, l) = y_of(o.begin + b, l).template cast<Scalar>();
    return 0.0;
  });
  S.push_back(std::move(s_store));
  Y.push_back(std::move(y_store));
  rho_.push_back(1.0 / sy);
  while (size() > capacity) drop_oldest();  // a smaller capacity than before
  scale_known_ = false;
}

Eigen::VectorXd LbfgsMemory::times(const Eigen::VectorXd& g, const Preconditioner& P) {
  return precision_ == LbfgsPrecision::single_precision ? times_with(Sf_, Yf_, g, P)
                                                        : times_with(S_, Y_, g, P);
}

template <class Stored>
Eigen::VectorXd LbfgsMemory::times_with(const std::deque<Stored>& S, const std::deque<Stored>& Y,
                                        const Eigen::VectorXd& g, const Preconditioner& P) {
  const Eigen::Index n = g.size();
  const OwnedBlocks o = owned(n);
  Eigen::VectorXd q;
  parallel_copy(g, q);
  const int m = size();
  const auto idx = [](int k) { return static_cast<std::size_t>(k); };
  // Global entry b of a stored vector is its entry b - offset_ (set_split).
  const auto dot = [&](const Stored& stored, const Eigen::VectorXd& whole) {
    return sum_owned(n, [&](Eigen::Index b, Eigen::Index l) {
      return stored_dot(stored, b - offset_, whole, b, l);
    });
  };
  // q += alpha x (x stored) over this process's blocks; then, when `next` is given, next . q.
  const auto update = [&](double alpha, const Stored& x, const Stored* next) {
    if (next == nullptr) {
      (void)sum_over_blocks(o.length(), [&](Eigen::Index b, Eigen::Index l) {
        stored_axpy(alpha, x, b, q, o.begin + b, l);
        return 0.0;
      });
      return 0.0;
    }
    return sum_owned(n, [&](Eigen::Index b, Eigen::Index l) {
      stored_axpy(alpha, x, b - offset_, q, b, l);
      return stored_dot(*next, b - offset_, q, b, l);
    });
  };
  std::vector<double> a(idx(m));
  // Newest to oldest: a_k = rho_k s_k.q, q -= a_k y_k; each update also forms s_{k-1}.q.
  double sq = m > 0 ? dot(S[idx(m - 1)], q) : 0.0;
  for (int k = m - 1; k >= 0; --k) {
    a[idx(k)] = rho_[idx(k)] * sq;
    sq = update(-a[idx(k)], Y[idx(k)], k > 0 ? &S[idx(k - 1)] : nullptr);
  }
  if (m > 0) {
    if (split_ != nullptr) split_->share_entries(q);  // P needs the whole vector
    if (!scale_known_) {
      // The newest y whole and in double, as P takes it.
      const auto scale_with = [&](const Eigen::VectorXd& y) {
        return dot(S.back(), y) / dot(Y.back(), P(y));
      };
      if (split_ != nullptr) {
        Eigen::VectorXd y = Eigen::VectorXd::Zero(n);
        y.segment(o.begin, o.length()) = Y.back().template cast<double>();
        split_->share_entries(y);
        scale_ = scale_with(y);
      } else if constexpr (std::is_same_v<Stored, Eigen::VectorXd>) {
        scale_ = scale_with(Y.back());
      } else {
        scale_ = scale_with(Y.back().template cast<double>());
      }
      scale_known_ = true;
    }
    q = P(q);
    parallel_scale(scale_, q);
  } else {
    q = P(q);
  }
  // Oldest to newest: b_k = rho_k y_k.q, q += (a_k - b_k) s_k; each update also forms
  // y_{k+1}.q.
  double yq = m > 0 ? dot(Y[0], q) : 0.0;
  for (int k = 0; k < m; ++k) {
    const double b = rho_[idx(k)] * yq;
    yq = update(a[idx(k)] - b, S[idx(k)], k + 1 < m ? &Y[idx(k + 1)] : nullptr);
  }
  if (m > 0 && split_ != nullptr) split_->share_entries(q);
  return q;
}

}  // namespace mresim::mess::detail
