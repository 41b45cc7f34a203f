#include "mresim/mess/solvers/hessian_assembly.hpp"

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <string>

#include "mresim/mess/system/system_energy.hpp"
#include "mresim/mess/terms/hessian_blocks.hpp"

namespace mresim::mess {

namespace {

// Adds scale x each block into the matrix's preallocated pattern.
class PatternSink final : public HessianBlockSink {
 public:
  PatternSink(ElasticMatrix& matrix, double scale) : matrix_(matrix), scale_(scale) {}
  void add(std::int64_t i, std::int64_t j, const Eigen::Matrix3d& block) override {
    const std::int64_t offset = matrix_.block_offset(i, j);
    if (offset < 0) {
      throw std::logic_error("ElasticMatrix: block (" + std::to_string(i) + ", " +
                             std::to_string(j) + ") is outside the lattice's pattern");
    }
    const std::int64_t length = matrix_.row_length(i);
    double* values = matrix_.mutable_values().data();
    for (int a = 0; a < 3; ++a) {
      for (int b = 0; b < 3; ++b) values[offset + a * length + b] += scale_ * block(a, b);
    }
  }

 private:
  ElasticMatrix& matrix_;
  double scale_;
};

}  // namespace

ElasticMatrix::ElasticMatrix(const lattice::Lattice& lat) {
  const std::int64_t n = lat.node_count();
  // Neighbour candidates per node: itself, the vertices of its cells, the other ends of its
  // springs; sorted and made unique per node below.
  std::vector<std::int64_t> count(static_cast<std::size_t>(n) + 1, 1);
  for (const auto& cell : lat.elements) {
    for (const std::int32_t v : cell) count[static_cast<std::size_t>(v) + 1] += 8;
  }
  const lattice::SpringSet& sp = lat.springs;
  for (std::size_t s = 0; s < sp.size(); ++s) {
    ++count[static_cast<std::size_t>(sp.first[s]) + 1];
    ++count[static_cast<std::size_t>(sp.second(s)) + 1];
  }
  count[0] = 0;
  for (std::int64_t k = 0; k < n; ++k) count[k + 1] += count[k];
  std::vector<std::int32_t> candidates(static_cast<std::size_t>(count.back()));
  std::vector<std::int64_t> fill(count.begin(), count.end() - 1);
  const auto push = [&](std::int32_t node, std::int32_t neighbour) {
    candidates[static_cast<std::size_t>(fill[static_cast<std::size_t>(node)]++)] = neighbour;
  };
  for (std::int64_t k = 0; k < n; ++k)
    push(static_cast<std::int32_t>(k), static_cast<std::int32_t>(k));
  for (const auto& cell : lat.elements) {
    for (const std::int32_t v : cell) {
      for (const std::int32_t w : cell) push(v, w);
    }
  }
  for (std::size_t s = 0; s < sp.size(); ++s) {
    push(sp.first[s], sp.second(s));
    push(sp.second(s), sp.first[s]);
  }
  neighbour_start_.assign(static_cast<std::size_t>(n) + 1, 0);
  neighbours_.reserve(static_cast<std::size_t>(27 * n));
  for (std::int64_t k = 0; k < n; ++k) {
    const auto first = candidates.begin() + count[static_cast<std::size_t>(k)];
    const auto last = candidates.begin() + count[static_cast<std::size_t>(k) + 1];
    std::sort(first, last);
    neighbours_.insert(neighbours_.end(), first, std::unique(first, last));
    neighbour_start_[static_cast<std::size_t>(k) + 1] =
        static_cast<std::int64_t>(neighbours_.size());
  }
  // Row 3 k + a: the 3 coordinates of every neighbour, in neighbour order.
  const std::int64_t entries = 9 * static_cast<std::int64_t>(neighbours_.size());
  if (entries > std::numeric_limits<std::int32_t>::max()) {
    throw std::invalid_argument("ElasticMatrix: " + std::to_string(n) +
                                " nodes exceed the 32-bit index range of the sparse matrix");
  }
  row_start_.resize(static_cast<std::size_t>(3 * n) + 1);
  columns_.resize(static_cast<std::size_t>(entries));
  std::int64_t at = 0;
  for (std::int64_t k = 0; k < n; ++k) {
    for (int a = 0; a < 3; ++a) {
      row_start_[static_cast<std::size_t>(3 * k + a)] = static_cast<std::int32_t>(at);
      for (std::int64_t e = neighbour_start_[static_cast<std::size_t>(k)];
           e < neighbour_start_[static_cast<std::size_t>(k) + 1]; ++e) {
        for (int b = 0; b < 3; ++b) {
          columns_[static_cast<std::size_t>(at++)] =
              3 * neighbours_[static_cast<std::size_t>(e)] + b;
        }
      }
    }
  }
  row_start_.back() = static_cast<std::int32_t>(at);
  values_.assign(static_cast<std::size_t>(entries), 0.0);
}

std::int64_t ElasticMatrix::block_offset(std::int64_t i, std::int64_t j) const {
  const auto first = neighbours_.begin() + neighbour_start_[static_cast<std::size_t>(i)];
  const auto last = neighbours_.begin() + neighbour_start_[static_cast<std::size_t>(i) + 1];
  const auto it = std::lower_bound(first, last, static_cast<std::int32_t>(j));
  if (it == last || *it != j) return -1;
  return row_start_[static_cast<std::size_t>(3 * i)] + 3 * (it - first);
}

void ElasticMatrix::assemble(const MessSystem& system, const std::vector<std::uint8_t>& free,
                             double scale) {
  if (free.size() + 1 != row_start_.size()) {
    throw std::invalid_argument("ElasticMatrix::assemble: expected one free flag per coordinate");
  }
  std::fill(values_.begin(), values_.end(), 0.0);
  PatternSink sink(*this, scale);
  system.add_elastic_hessian_blocks(sink);
  impose_identity(free);
}

void ElasticMatrix::impose_identity(const std::vector<std::uint8_t>& free) {
  double diagonal_sum = 0.0;
  std::int64_t free_count = 0;
  const auto rows3 = static_cast<std::int64_t>(free.size());
  for (std::int64_t r = 0; r < rows3; ++r) {
    if (free[static_cast<std::size_t>(r)] == 0) continue;
    const std::int64_t node = r / 3;
    diagonal_sum += values_[static_cast<std::size_t>(block_offset(node, node) +
                                                     (r % 3) * row_length(node) + r % 3)];
    ++free_count;
  }
  const double identity = free_count > 0 ? diagonal_sum / static_cast<double>(free_count) : 1.0;
  for (std::int64_t r = 0; r < rows3; ++r) {
    const bool row_free = free[static_cast<std::size_t>(r)] != 0;
    for (std::int32_t e = row_start_[static_cast<std::size_t>(r)];
         e < row_start_[static_cast<std::size_t>(r) + 1]; ++e) {
      const std::int32_t c = columns_[static_cast<std::size_t>(e)];
      if (row_free && free[static_cast<std::size_t>(c)] != 0) continue;
      values_[static_cast<std::size_t>(e)] = c == r ? identity : 0.0;
    }
  }
}

Eigen::VectorXd ElasticMatrix::multiply(const Eigen::VectorXd& x) const {
  Eigen::VectorXd y = Eigen::VectorXd::Zero(rows());
  for (std::int32_t r = 0; r < rows(); ++r) {
    double sum = 0.0;
    for (std::int32_t e = row_start_[static_cast<std::size_t>(r)];
         e < row_start_[static_cast<std::size_t>(r) + 1]; ++e) {
      sum += values_[static_cast<std::size_t>(e)] * x[columns_[static_cast<std::size_t>(e)]];
    }
    y[r] = sum;
  }
  return y;
}

}  // namespace mresim::mess
