#include "mresim/mess/solvers/lbfgs_memory.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cstddef>
#include <utility>
#include <vector>

#include "mresim/mess/solvers/vector_algebra.hpp"
#include "mresim/mess/terms/simd_clones.hpp"

namespace mresim::mess::detail {

namespace {

// The products' kernels on one block of l entries, in double whatever the stored precision.
// A dot product keeps 32 partial sums in a fixed order (the same for every thread count): with
// four, each sum's chain of additions left the vector units idle, and the 40 dot products of a
// product at full size took 1.6x the time (measured). 16 partial sums are about 5 % faster than
// 32 but round so that the scaled-down Fig. 4.19 example's first step (the pair's jump into
// contact at 140 mT) ends in a neighbouring contact equilibrium 13 nm closer and 0.2 % higher in
// energy; 4, 8 and 32 end in the one the example describes (docs/performance.md, "One
// application of the preconditioner per iteration"). Compiled for AVX-512, AVX2 and the
// baseline (simd_clones.hpp) without fused multiply-adds (CMakeLists.txt), so every clone gives
// the baseline's bits.
template <class A, class B>
inline double dot_kernel(const A* a, const B* b, Eigen::Index l) {
  constexpr Eigen::Index kPartials = 32;
  std::array<double, kPartials> sum{};
  Eigen::Index i = 0;
  for (; i + kPartials <= l; i += kPartials) {
    for (Eigen::Index k = 0; k < kPartials; ++k) {
      sum[static_cast<std::size_t>(k)] +=
          static_cast<double>(a[i + k]) * static_cast<double>(b[i + k]);
    }
  }
  for (; i < l; ++i) sum[0] += static_cast<double>(a[i]) * static_cast<double>(b[i]);
  double total = 0.0;
  for (const double partial : sum) total += partial;
  return total;
}

MRESIM_SIMD_CLONES double block_dot(const float* a, const double* b, Eigen::Index l) {
  return dot_kernel(a, b, l);
}
MRESIM_SIMD_CLONES double block_dot(const float* a, const float* b, Eigen::Index l) {
  return dot_kernel(a, b, l);
}
MRESIM_SIMD_CLONES double block_dot(const double* a, const double* b, Eigen::Index l) {
  return dot_kernel(a, b, l);
}

// w[0, l) += alpha x[0, l) + beta y[0, l)
template <class A>
inline void axpy2_kernel(double alpha, const A* x, double beta, const A* y, double* w,
                         Eigen::Index l) {
  for (Eigen::Index i = 0; i < l; ++i) {
    w[i] += alpha * static_cast<double>(x[i]) + beta * static_cast<double>(y[i]);
  }
}

MRESIM_SIMD_CLONES void block_axpy2(double alpha, const float* x, double beta, const float* y,
                                    double* w, Eigen::Index l) {
  axpy2_kernel(alpha, x, beta, y, w, l);
}
MRESIM_SIMD_CLONES void block_axpy2(double alpha, const double* x, double beta, const double* y,
                                    double* w, Eigen::Index l) {
  axpy2_kernel(alpha, x, beta, y, w, l);
}

// A block of a whole vector rounded to the stored precision, back in double: what storing it
// keeps.
template <class Scalar>
void round_block(const double* v, Eigen::Index l, std::array<double, kSumBlock>& out) {
  for (Eigen::Index i = 0; i < l; ++i) {
    out[static_cast<std::size_t>(i)] = static_cast<double>(static_cast<Scalar>(v[i]));
  }
}

}  // namespace

LbfgsMemory::Fingerprint LbfgsMemory::fingerprint(const Eigen::VectorXd& v) {
  Fingerprint f;
  f.size = v.size();
  if (v.size() == 0) return f;
  for (int k = 0; k < kFingerprintEntries; ++k) {
    const Eigen::Index at = (static_cast<Eigen::Index>(k) * (v.size() - 1)) /
                            static_cast<Eigen::Index>(kFingerprintEntries - 1);
    f.bits[static_cast<std::size_t>(k)] = std::bit_cast<std::uint64_t>(v[at]);
  }
  return f;
}

void LbfgsMemory::clear() {
  S_.clear();
  Z_.clear();
  Sf_.clear();
  Zf_.clear();
  z_known_.clear();
  sy_.resize(0, 0);
  yz_.resize(0, 0);
  newest_by_difference_ = false;
}

void LbfgsMemory::set_precision(LbfgsPrecision precision) {
  if (precision != precision_) clear();
  precision_ = precision;
}

void LbfgsMemory::preconditioner_changed() {
  clear();
  last_pg_known_ = false;
  last_pg_.resize(0);
}

void LbfgsMemory::set_split(std::shared_ptr<const BlockSplit> split) {
  preconditioner_changed();
  split_ = std::move(split);
}

Eigen::Index LbfgsMemory::stored_entries() const {
  Eigen::Index total = 0;
  for (const auto* pairs : {&S_, &Z_}) {
    for (const auto& v : *pairs) total += v.size();
  }
  for (const auto* pairs : {&Sf_, &Zf_}) {
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
    Zf_.pop_front();
  } else {
    S_.pop_front();
    Z_.pop_front();
  }
  z_known_.pop_front();
  const Eigen::Index m = sy_.rows() - 1;
  sy_ = sy_.bottomRightCorner(m, m).eval();
  yz_ = yz_.bottomRightCorner(m, m).eval();
}

OwnedBlocks LbfgsMemory::owned(Eigen::Index n) const {
  return split_ != nullptr ? split_->owned(n) : all_blocks(n);
}

template <class Block>
std::vector<double> LbfgsMemory::sums_owned(Eigen::Index n, int count, Block&& block) const {
  const auto c = static_cast<std::size_t>(count);
  std::vector<double> total(c, 0.0);
  if (n <= 0 || count == 0) return total;
  const auto blocks = static_cast<std::size_t>(all_blocks(n).last_block);
  const OwnedBlocks o = owned(n);
  std::vector<double> partial(blocks * c, 0.0);
#pragma omp parallel for schedule(static) if (o.length() >= kParallelMinimum)
  for (Eigen::Index b = o.first_block; b < o.last_block; ++b) {
    const Eigen::Index begin = b * kSumBlock;
    block(begin, std::min(kSumBlock, n - begin), partial.data() + static_cast<std::size_t>(b) * c);
  }
  if (split_ != nullptr) {
    std::vector<double> block_sums(blocks);
    for (std::size_t k = 0; k < c; ++k) {
      for (std::size_t b = 0; b < blocks; ++b) block_sums[b] = partial[b * c + k];
      split_->share_block_sums(block_sums, n);
      for (std::size_t b = 0; b < blocks; ++b) partial[b * c + k] = block_sums[b];
    }
  }
  for (std::size_t k = 0; k < c; ++k) {
    for (std::size_t b = 0; b < blocks; ++b) total[k] += partial[b * c + k];
  }
  return total;
}

void LbfgsMemory::add(double alpha, const Eigen::VectorXd& d, const Eigen::VectorXd& g_new,
                      const Eigen::VectorXd& g_old, int capacity) {
  if (precision_ == LbfgsPrecision::single_precision) {
    add_to(Sf_, Zf_, alpha, d, g_new, g_old, capacity);
  } else {
    add_to(S_, Z_, alpha, d, g_new, g_old, capacity);
  }
}

template <class Stored>
void LbfgsMemory::add_to(std::deque<Stored>& S, std::deque<Stored>& Z, double alpha,
                         const Eigen::VectorXd& d, const Eigen::VectorXd& g_new,
                         const Eigen::VectorXd& g_old, int capacity) {
  using Scalar = typename Stored::Scalar;
  const Eigen::Index n = d.size();
  // s and y as they will be stored (a no-op cast in double precision): s.y and y.y are those
  // of the stored pair.
  const auto s_of = [&](Eigen::Index begin, Eigen::Index length) {
    return (alpha * d.segment(begin, length)).template cast<Scalar>().template cast<double>();
  };
  const auto y_of = [&](Eigen::Index begin, Eigen::Index length) {
    return (g_new.segment(begin, length) - g_old.segment(begin, length))
        .template cast<Scalar>()
        .template cast<double>();
  };
  const std::vector<double> sums =
      sums_owned(n, 2, [&](Eigen::Index b, Eigen::Index l, double* out) {
        out[0] = s_of(b, l).dot(y_of(b, l));
        out[1] = y_of(b, l).squaredNorm();
      });
  const double sy = sums[0];
  const double yy = sums[1];
  if (!(sy > 1e-12 * yy && sy > 0.0)) return;
  const OwnedBlocks o = owned(n);
  if (!S.empty() && S.front().size() != o.length()) clear();  // another problem size
  Stored s_store;
  Stored y_store;
  if (size() >= capacity && !S.empty()) {  // reuse the oldest pair's storage
    s_store = std::move(S.front());
    y_store = std::move(Z.front());
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
  Z.push_back(std::move(y_store));  // y until its z is formed
  z_known_.push_back(false);
  const Eigen::Index m = size();
  sy_.conservativeResize(m, m);
  yz_.conservativeResize(m, m);
  sy_.row(m - 1).setZero();
  sy_.col(m - 1).setZero();
  yz_.row(m - 1).setZero();
  yz_.col(m - 1).setZero();
  sy_(m - 1, m - 1) = sy;
  while (size() > capacity) drop_oldest();  // a smaller capacity than before
  newest_by_difference_ = last_pg_known_ && last_pg_.size() == n && fingerprint(g_old) == last_g_;
  newest_g_new_ = fingerprint(g_new);
}

Eigen::VectorXd LbfgsMemory::times(const Eigen::VectorXd& g, const Preconditioner& P) {
  return precision_ == LbfgsPrecision::single_precision ? times_with(Sf_, Zf_, g, P)
                                                        : times_with(S_, Z_, g, P);
}

template <class Stored>
void LbfgsMemory::complete_by_applying(const std::deque<Stored>& S, std::deque<Stored>& Z, int j,
                                       Eigen::Index n, const Preconditioner& P) {
  using Scalar = typename Stored::Scalar;
  const auto idx = [](int k) { return static_cast<std::size_t>(k); };
  const OwnedBlocks o = owned(n);
  Eigen::VectorXd y = split_ != nullptr ? Eigen::VectorXd::Zero(n) : Eigen::VectorXd(n);
  (void)sum_over_blocks(o.length(), [&](Eigen::Index b, Eigen::Index l) {
    y.segment(o.begin + b, l) = Z[idx(j)].segment(b, l).template cast<double>();
    return 0.0;
  });
  if (split_ != nullptr) split_->share_entries(y);  // P needs the whole vector
  const Eigen::VectorXd z = P(y);
  // The sums: s_i.y_j for i < j (R's column j), y_j.z_k for every other k whose z is known,
  // y_j.z_j.
  std::vector<int> known;
  for (int k = 0; k < size(); ++k) {
    if (k != j && z_known_[idx(k)]) known.push_back(k);
  }
  const int count = j + static_cast<int>(known.size()) + 1;
  const std::vector<double> sums =
      sums_owned(n, count, [&](Eigen::Index gb, Eigen::Index l, double* out) {
        const Eigen::Index lb = gb - offset_;
        const Scalar* yj = Z[idx(j)].data() + lb;
        std::array<double, kSumBlock> zb{};
        round_block<Scalar>(z.data() + gb, l, zb);
        for (int i = 0; i < j; ++i) out[i] = block_dot(S[idx(i)].data() + lb, yj, l);
        for (std::size_t k = 0; k < known.size(); ++k) {
          out[idx(j) + k] = block_dot(yj, Z[idx(known[k])].data() + lb, l);
        }
        out[count - 1] = block_dot(yj, zb.data(), l);
        Scalar* zj = Z[idx(j)].data() + lb;  // the pair's y is no longer needed
        for (Eigen::Index i = 0; i < l; ++i)
          zj[i] = static_cast<Scalar>(zb[static_cast<std::size_t>(i)]);
      });
  for (int i = 0; i < j; ++i) sy_(i, j) = sums[idx(i)];
  for (std::size_t k = 0; k < known.size(); ++k) {
    yz_(j, known[k]) = sums[idx(j) + k];
    yz_(known[k], j) = sums[idx(j) + k];
  }
  yz_(j, j) = sums[idx(count - 1)];
  z_known_[idx(j)] = true;
}

// The newest pair's z on one block [gb, gb + l), as stored: P g_new - P g_old, where r = P g_new
// and last_pg_ = P g_old.
template <class Scalar>
void LbfgsMemory::newest_z_block(const Eigen::VectorXd& r, Eigen::Index gb, Eigen::Index l,
                                 std::array<double, kSumBlock>& zb) const {
  for (Eigen::Index i = 0; i < l; ++i) {
    zb[static_cast<std::size_t>(i)] =
        static_cast<double>(static_cast<Scalar>(r[gb + i] - last_pg_[gb + i]));
  }
}

template <class Stored>
Eigen::VectorXd LbfgsMemory::times_with(const std::deque<Stored>& S, std::deque<Stored>& Z,
                                        const Eigen::VectorXd& g, const Preconditioner& P) {
  const Eigen::Index n = g.size();
  const int m = size();
  Eigen::VectorXd r = P(g);
  const Fingerprint at = fingerprint(g);
  // The newest pair's z by difference if the products were taken in L-BFGS's order (header).
  const bool by_difference = m > 0 && !z_known_.back() && newest_by_difference_ && last_pg_known_ &&
                             last_pg_.size() == n && at == newest_g_new_;
  for (int j = 0; j < m; ++j) {
    const bool pending = !z_known_[static_cast<std::size_t>(j)];
    if (pending && !(by_difference && j == m - 1)) complete_by_applying(S, Z, j, n, P);
  }
  const ProductDots dots = product_dots(S, Z, g, r, by_difference);
  Eigen::VectorXd out = product_sum(S, Z, r, by_difference, coefficients(dots));
  if (split_ != nullptr) split_->share_entries(out);
  last_pg_ = std::move(r);
  last_g_ = at;
  last_pg_known_ = true;
  newest_by_difference_ = false;
  return out;
}

// Sweep 1, one pass per pair (a pass over one pair's two vectors at a time streams from memory
// about twice as fast as one over all pairs' entries block by block, measured): s_i.g and z_i.g;
// for a newest pair by difference also s_i.y_new and y_new.z_i (i < newest) and y_new.z_new,
// its entries of R and Y^T Z.
template <class Stored>
LbfgsMemory::ProductDots LbfgsMemory::product_dots(const std::deque<Stored>& S,
                                                   const std::deque<Stored>& Z,
                                                   const Eigen::VectorXd& g,
                                                   const Eigen::VectorXd& r, bool by_difference) {
  using Scalar = typename Stored::Scalar;
  const auto idx = [](int k) { return static_cast<std::size_t>(k); };
  const int m = size();
  const int newest = m - 1;
  ProductDots dots{Eigen::VectorXd(m), Eigen::VectorXd(m)};
  for (int i = 0; i < m; ++i) {
    const bool newest_by_difference = by_difference && i == newest;
    const int count = newest_by_difference ? 3 : (by_difference ? 4 : 2);
    const std::vector<double> sums =
        sums_owned(g.size(), count, [&](Eigen::Index gb, Eigen::Index l, double* out) {
          const Eigen::Index lb = gb - offset_;
          const double* gg = g.data() + gb;
          const Scalar* si = S[idx(i)].data() + lb;
          out[0] = block_dot(si, gg, l);
          const Scalar* zi = Z[idx(i)].data() + lb;  // y_new for the newest pair by difference
          if (newest_by_difference) {
            std::array<double, kSumBlock> zb{};
            newest_z_block<Scalar>(r, gb, l, zb);
            out[1] = block_dot(zb.data(), gg, l);
            out[2] = block_dot(zi, zb.data(), l);
            return;
          }
          out[1] = block_dot(zi, gg, l);
          if (!by_difference) return;
          const Scalar* y_new = Z[idx(newest)].data() + lb;
          out[2] = block_dot(si, y_new, l);
          out[3] = block_dot(y_new, zi, l);
        });
    dots.sg[i] = sums[0];
    dots.zg[i] = sums[1];
    if (newest_by_difference) {
      yz_(newest, newest) = sums[2];
    } else if (by_difference) {
      sy_(i, newest) = sums[2];
      yz_(newest, i) = sums[3];
      yz_(i, newest) = sums[3];
    }
  }
  if (by_difference) z_known_.back() = true;
  return dots;
}

// The small system: gamma, and H g = gamma P g + S p + Z c with a = R^-1 S^T g,
// p = R^-T ((D + gamma Y^T Z) a - gamma Z^T g), c = -gamma a.
LbfgsMemory::ProductCoefficients LbfgsMemory::coefficients(const ProductDots& dots) const {
  ProductCoefficients c;
  const Eigen::Index m = dots.sg.size();
  if (m == 0) return c;  // H0 = P without pairs
  c.gamma = sy_(m - 1, m - 1) / yz_(m - 1, m - 1);
  const Eigen::VectorXd a = sy_.triangularView<Eigen::Upper>().solve(dots.sg);
  const Eigen::VectorXd t =
      sy_.diagonal().cwiseProduct(a) + c.gamma * (yz_ * a) - c.gamma * dots.zg;
  c.s = sy_.transpose().triangularView<Eigen::Lower>().solve(t);
  c.z = -c.gamma * a;
  return c;
}

// Sweep 2: H g over this process's blocks, one pass per pair (the newest pair's z stored first
// when it comes by difference).
template <class Stored>
Eigen::VectorXd LbfgsMemory::product_sum(const std::deque<Stored>& S, std::deque<Stored>& Z,
                                         const Eigen::VectorXd& r, bool by_difference,
                                         const ProductCoefficients& c) const {
  using Scalar = typename Stored::Scalar;
  const Eigen::Index n = r.size();
  const OwnedBlocks o = owned(n);
  const int m = size();
  const auto idx = [](int k) { return static_cast<std::size_t>(k); };
  Eigen::VectorXd out = split_ != nullptr ? Eigen::VectorXd::Zero(n) : Eigen::VectorXd(n);
  for (int i = 0; i < std::max(m, 1); ++i) {
    (void)sum_over_blocks(o.length(), [&](Eigen::Index lb, Eigen::Index l) {
      const Eigen::Index gb = o.begin + lb;
      double* ob = out.data() + gb;
      if (i == 0) {  // the first pass starts from gamma P g
        const double* rb = r.data() + gb;
#pragma omp simd
        for (Eigen::Index k = 0; k < l; ++k) ob[k] = c.gamma * rb[k];
      }
      if (m == 0) return 0.0;
      Scalar* zi = Z[idx(i)].data() + lb;
      if (by_difference && i == m - 1) {
        std::array<double, kSumBlock> zb{};
        newest_z_block<Scalar>(r, gb, l, zb);
        for (Eigen::Index k = 0; k < l; ++k) {
          zi[k] = static_cast<Scalar>(zb[static_cast<std::size_t>(k)]);
        }
      }
      block_axpy2(c.s[i], S[idx(i)].data() + lb, c.z[i], zi, ob, l);
      return 0.0;
    });
  }
  return out;
}

}  // namespace mresim::mess::detail
