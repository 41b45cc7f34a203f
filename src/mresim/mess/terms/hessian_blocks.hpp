#pragma once

// The elastic terms' Hessians delivered as 3 x 3 node blocks: H[3 i + a][3 j + b] += B(a, b)
// for every block (i, j, B) a term produces. A sink decides where the blocks go: Eigen
// triplets for tests and small systems (TripletSink), or a preallocated sparse pattern for
// the Newton solver's preconditioner (solvers/hessian_assembly.hpp), which never holds the
// 36 entries per spring and 576 per cell that triplets would need.

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <cstdint>
#include <vector>

namespace mresim::mess {

class HessianBlockSink {
 public:
  HessianBlockSink() = default;
  HessianBlockSink(const HessianBlockSink&) = default;
  HessianBlockSink& operator=(const HessianBlockSink&) = default;
  HessianBlockSink(HessianBlockSink&&) = default;
  HessianBlockSink& operator=(HessianBlockSink&&) = default;
  virtual ~HessianBlockSink() = default;

  // Adds `block` at rows 3 i .. 3 i + 2, columns 3 j .. 3 j + 2.
  virtual void add(std::int64_t i, std::int64_t j, const Eigen::Matrix3d& block) = 0;

  // A sink that keeps only the blocks between some nodes says so here: then add(i, j, B) has
  // no effect unless takes_node(i) and takes_node(j), and a term may skip computing its blocks
  // when it has no node the sink takes (every term delivers a block (n, n) for each of its
  // nodes n, so such a term changes nothing). The blocks that arrive, and their order, stay
  // those of the whole sweep, so the sums are bitwise the same. Why: the contact gaps'
  // blocks (solvers/contact_gap_blocks.hpp) need a few thousand of a lattice's nodes, and the
  // whole sweep over a full-size lattice took seconds per gap.
  [[nodiscard]] virtual bool filters_nodes() const { return false; }
  [[nodiscard]] virtual bool takes_node(std::int64_t /*n*/) const { return true; }
};

// Appends 9 triplets per block (duplicates are summed by Eigen's setFromTriplets).
class TripletSink final : public HessianBlockSink {
 public:
  explicit TripletSink(std::vector<Eigen::Triplet<double>>& entries) : entries_(entries) {}
  void add(std::int64_t i, std::int64_t j, const Eigen::Matrix3d& block) override {
    for (int b = 0; b < 3; ++b) {
      for (int a = 0; a < 3; ++a) entries_.emplace_back(3 * i + a, 3 * j + b, block(a, b));
    }
  }

 private:
  std::vector<Eigen::Triplet<double>>& entries_;
};

}  // namespace mresim::mess
