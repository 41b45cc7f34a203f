#include "mresim/mess/solvers/contact_gap_blocks.hpp"

#include <Eigen/SparseCore>
#include <cmath>
#include <utility>

#include "mresim/mess/terms/hessian_blocks.hpp"

namespace mresim::mess {

namespace {

// Keeps the blocks (i, j) whose two nodes are both in the gap, as triplets of its local
// coordinates (3 k + a for its k-th node), times `scale`.
class GapSink final : public HessianBlockSink {
 public:
  GapSink(const std::vector<std::int32_t>& local, double scale,
          std::vector<Eigen::Triplet<double>>& entries)
      : local_(local), scale_(scale), entries_(entries) {}
  void add(std::int64_t i, std::int64_t j, const Eigen::Matrix3d& block) override {
    const std::int32_t li = local_[static_cast<std::size_t>(i)];
    const std::int32_t lj = local_[static_cast<std::size_t>(j)];
    if (li < 0 || lj < 0) return;
    for (int b = 0; b < 3; ++b) {
      for (int a = 0; a < 3; ++a) {
        entries_.emplace_back(3 * li + a, 3 * lj + b, scale_ * block(a, b));
      }
    }
  }

 private:
  const std::vector<std::int32_t>& local_;
  double scale_;
  std::vector<Eigen::Triplet<double>>& entries_;
};

}  // namespace

std::vector<std::int64_t> ContactGapBlocks::gap_nodes(const MessSystem& system, const DofMap& map,
                                                      const Eigen::Vector3d& first,
                                                      const Eigen::Vector3d& second) {
  const lattice::Lattice& lat = system.lattice();
  const double radius = lat.particle_radius;
  const Eigen::Vector3d mid = 0.5 * (first + second);
  const Eigen::Vector3d axis = (second - first).normalized();
  const Eigen::Matrix3Xd& x = system.positions();
  std::vector<std::int64_t> nodes;
  for (std::int64_t n = 0; n < lat.node_count(); ++n) {
    if (lat.particle_of_node[static_cast<std::size_t>(n)] >= 0) continue;
    const Eigen::Vector3d d = x.col(n) - mid;
    const double along = d.dot(axis);
    if (std::abs(along) >= kGapHalfLength * radius ||
        (d - along * axis).norm() >= kGapRadius * radius) {
      continue;
    }
    bool free = true;
    for (int a = 0; a < 3 && free; ++a) free = map.own_dof_of_coordinate(3 * n + a) >= 0;
    if (free) nodes.push_back(n);
  }
  return nodes;
}

ContactGapBlocks::ContactGapBlocks(const MessSystem& system, const DofMap& map,
                                   double force_scale) {
  const lattice::Lattice& lat = system.lattice();
  const Eigen::Matrix3Xd centres = system.particle_centres(CentreRule::all_nodes);
  const double contact = kContactSeparation * lat.particle_radius;
  const double scale = lat.element_length / force_scale;
  std::vector<std::int32_t> local;  // node -> its index in the current gap, or -1
  for (Eigen::Index p = 0; p < centres.cols(); ++p) {
    for (Eigen::Index q = p + 1; q < centres.cols(); ++q) {
      if ((centres.col(q) - centres.col(p)).norm() >= contact) continue;
      const std::vector<std::int64_t> nodes =
          gap_nodes(system, map, centres.col(p), centres.col(q));
      if (nodes.empty()) continue;
      local.assign(static_cast<std::size_t>(lat.node_count()), -1);
      Gap gap;
      for (std::size_t k = 0; k < nodes.size(); ++k) {
        local[static_cast<std::size_t>(nodes[k])] = static_cast<std::int32_t>(k);
        for (int a = 0; a < 3; ++a) gap.dofs.push_back(map.own_dof_of_coordinate(3 * nodes[k] + a));
      }
      std::vector<Eigen::Triplet<double>> entries;
      GapSink sink(local, scale, entries);
      system.add_elastic_hessian_blocks(sink);
      const auto size = static_cast<Eigen::Index>(gap.dofs.size());
      Eigen::SparseMatrix<double> block(size, size);
      block.setFromTriplets(entries.begin(), entries.end());
      gap.factor = std::make_unique<Eigen::SimplicialLLT<Eigen::SparseMatrix<double>>>(block);
      if (gap.factor->info() != Eigen::Success) {
        ++left_out_;  // not positive definite (header)
        continue;
      }
      gaps_.push_back(std::move(gap));
    }
  }
}

void ContactGapBlocks::add_to(const Eigen::VectorXd& v, Eigen::VectorXd& w) const {
  for (const Gap& gap : gaps_) {
    const auto size = static_cast<Eigen::Index>(gap.dofs.size());
    Eigen::VectorXd r(size);
    for (Eigen::Index k = 0; k < size; ++k) r[k] = v[gap.dofs[static_cast<std::size_t>(k)]];
    const Eigen::VectorXd y = gap.factor->solve(r);
    for (Eigen::Index k = 0; k < size; ++k) w[gap.dofs[static_cast<std::size_t>(k)]] += y[k];
  }
}

Eigen::Index ContactGapBlocks::dofs() const {
  Eigen::Index count = 0;
  for (const Gap& gap : gaps_) count += static_cast<Eigen::Index>(gap.dofs.size());
  return count;
}

}  // namespace mresim::mess
