#include "mresim/mess/solvers/lbfgs_memory.hpp"

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

void LbfgsMemory::drop_oldest() {
  S_.pop_front();
  Y_.pop_front();
  rho_.pop_front();
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
  const double sy = sum_over_blocks(
      n, [&](Eigen::Index b, Eigen::Index l) { return s_of(b, l).dot(y_of(b, l)); });
  const double yy =
      sum_over_blocks(n, [&](Eigen::Index b, Eigen::Index l) { return y_of(b, l).squaredNorm(); });
  if (!(sy > 1e-12 * yy && sy > 0.0)) return;
  Eigen::VectorXd s_store;
  Eigen::VectorXd y_store;
  if (size() >= capacity && !S_.empty()) {  // reuse the oldest pair's storage
    s_store = std::move(S_.front());
    y_store = std::move(Y_.front());
    drop_oldest();
  }
  s_store.resize(n);
  y_store.resize(n);
  (void)sum_over_blocks(n, [&](Eigen::Index b, Eigen::Index l) {
    s_store.segment(b, l) = s_of(b, l);
    y_store.segment(b, l) = y_of(b, l);
    return 0.0;
  });
  S_.push_back(std::move(s_store));
  Y_.push_back(std::move(y_store));
  rho_.push_back(1.0 / sy);
  while (size() > capacity) drop_oldest();  // a smaller capacity than before
  scale_known_ = false;
}

Eigen::VectorXd LbfgsMemory::times(const Eigen::VectorXd& g, const Preconditioner& P) {
  Eigen::VectorXd q;
  parallel_copy(g, q);
  const int m = size();
  const auto at = [](int k) { return static_cast<std::size_t>(k); };
  std::vector<double> a(at(m));
  // Newest to oldest: a_k = rho_k s_k.q, q -= a_k y_k; each update also forms s_{k-1}.q.
  double sq = m > 0 ? parallel_dot(S_[at(m - 1)], q) : 0.0;
  for (int k = m - 1; k >= 0; --k) {
    a[at(k)] = rho_[at(k)] * sq;
    if (k > 0) {
      sq = parallel_axpy_dot(-a[at(k)], Y_[at(k)], q, S_[at(k - 1)]);
    } else {
      parallel_axpy(-a[at(k)], Y_[at(k)], q);
    }
  }
  if (m > 0) {
    if (!scale_known_) {
      scale_ = parallel_dot(S_.back(), Y_.back()) / parallel_dot(Y_.back(), P(Y_.back()));
      scale_known_ = true;
    }
    q = P(q);
    parallel_scale(scale_, q);
  } else {
    q = P(q);
  }
  // Oldest to newest: b_k = rho_k y_k.q, q += (a_k - b_k) s_k; each update also forms
  // y_{k+1}.q.
  double yq = m > 0 ? parallel_dot(Y_[0], q) : 0.0;
  for (int k = 0; k < m; ++k) {
    const double b = rho_[at(k)] * yq;
    if (k + 1 < m) {
      yq = parallel_axpy_dot(a[at(k)] - b, S_[at(k)], q, Y_[at(k + 1)]);
    } else {
      parallel_axpy(a[at(k)] - b, S_[at(k)], q);
    }
  }
  return q;
}

}  // namespace mresim::mess::detail
