#include "mresim/mess/solvers/contact_gap_blocks.hpp"

#include <Eigen/SparseCore>
#include <array>
#include <cmath>
#include <utility>

#include "mresim/mess/terms/hessian_blocks.hpp"

namespace mresim::mess {

namespace {

// Sums the node blocks (i, j) whose two nodes are both in the gap, times `scale`, into 27 blocks
// per gap node (j is one of i's 27 lattice neighbours, springs and cells reaching one plane
// along each axis): 1.9 kB per gap node, where the 9 triplets per block a term delivers would
// take about 17 kB.
class GapSink final : public HessianBlockSink {
 public:
  GapSink(const lattice::GridShape& shape, const std::vector<std::int32_t>& local,
          std::size_t nodes, double scale)
      : shape_(shape), local_(local), scale_(scale), blocks_(27 * nodes, Eigen::Matrix3d::Zero()) {}
  void add(std::int64_t i, std::int64_t j, const Eigen::Matrix3d& block) override {
    const std::int32_t li = local_[static_cast<std::size_t>(i)];
    if (li < 0 || local_[static_cast<std::size_t>(j)] < 0) return;
    blocks_[27 * static_cast<std::size_t>(li) + neighbour_code(i, j)] += scale_ * block;
  }
  // Only the gap's nodes: the kernels skip the rest of the lattice.
  [[nodiscard]] bool filters_nodes() const override { return true; }
  [[nodiscard]] bool takes_node(std::int64_t n) const override {
    return local_[static_cast<std::size_t>(n)] >= 0;
  }
  // The lower triangle of the gap's block of the Hessian, in single precision (all the factor
  // reads): row and column 3 k + a for the k-th gap node.
  [[nodiscard]] Eigen::SparseMatrix<float> lower_matrix(
      const std::vector<std::int64_t>& nodes) const {
    std::vector<Eigen::Triplet<float>> entries;
    for (std::size_t k = 0; k < nodes.size(); ++k) {
      const std::array<int, 3> at = shape_.node_coordinates(static_cast<int>(nodes[k]));
      for (std::size_t code = 0; code < 27; ++code) {
        const Eigen::Matrix3d& b = blocks_[27 * k + code];
        if (b.isZero(0.0)) continue;
        const int j = shape_.node_index(at[0] + static_cast<int>(code % 3) - 1,
                                        at[1] + static_cast<int>((code / 3) % 3) - 1,
                                        at[2] + static_cast<int>(code / 9) - 1);
        const std::int32_t lj = local_[static_cast<std::size_t>(j)];
        for (int c = 0; c < 3; ++c) {
          for (int r = 0; r < 3; ++r) {
            const int row = 3 * static_cast<int>(k) + r;
            const int column = 3 * lj + c;
            if (row >= column) entries.emplace_back(row, column, static_cast<float>(b(r, c)));
          }
        }
      }
    }
    const auto size = static_cast<Eigen::Index>(3 * nodes.size());
    Eigen::SparseMatrix<float> m(size, size);
    m.setFromTriplets(entries.begin(), entries.end());
    return m;
  }

 private:
  // Where j lies from i: (dx + 1) + 3 (dy + 1) + 9 (dz + 1).
  [[nodiscard]] std::size_t neighbour_code(std::int64_t i, std::int64_t j) const {
    const std::array<int, 3> a = shape_.node_coordinates(static_cast<int>(i));
    const std::array<int, 3> b = shape_.node_coordinates(static_cast<int>(j));
    const int code = (b[0] - a[0] + 1) + 3 * (b[1] - a[1] + 1) + 9 * (b[2] - a[2] + 1);
    return static_cast<std::size_t>(code);
  }
  const lattice::GridShape& shape_;
  const std::vector<std::int32_t>& local_;
  double scale_;
  std::vector<Eigen::Matrix3d> blocks_;
};

}  // namespace

std::vector<std::int64_t> ContactGapBlocks::gap_nodes(const MessSystem& system, const DofMap& map,
                                                      const Eigen::Matrix3Xd& x,
                                                      const Eigen::Vector3d& first,
                                                      const Eigen::Vector3d& second) {
  const lattice::Lattice& lat = system.lattice();
  const double radius = lat.particle_radius;
  const Eigen::Vector3d mid = 0.5 * (first + second);
  const Eigen::Vector3d axis = (second - first).normalized();
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

std::vector<std::pair<int, int>> ContactGapBlocks::contact_pairs(const Eigen::Matrix3Xd& centres,
                                                                 double particle_radius) {
  const double contact = kContactSeparation * particle_radius;
  std::vector<std::pair<int, int>> pairs;
  for (Eigen::Index p = 0; p < centres.cols(); ++p) {
    for (Eigen::Index q = p + 1; q < centres.cols(); ++q) {
      if ((centres.col(q) - centres.col(p)).norm() < contact) {
        pairs.emplace_back(static_cast<int>(p), static_cast<int>(q));
      }
    }
  }
  return pairs;
}

ContactGapBlocks::ContactGapBlocks(const MessSystem& system, const DofMap& map, double force_scale,
                                   const Eigen::Matrix3Xd& at) {
  const lattice::Lattice& lat = system.lattice();
  const Eigen::Matrix3Xd centres = system.particle_centres_at(at, CentreRule::all_nodes);
  const std::vector<std::pair<int, int>> pairs = contact_pairs(centres, lat.particle_radius);
  // The gaps are independent: with several pairs in contact (the helix's clusters) each thread
  // builds whole gaps, in the pairs' order; each gap is the same for any number of threads.
  std::vector<Gap> built(pairs.size());
  std::vector<char> factored(pairs.size(), 0);
  const auto count = static_cast<std::int64_t>(pairs.size());
#pragma omp parallel for schedule(dynamic) if (count > 1)
  for (std::int64_t k = 0; k < count; ++k) {
    const auto [p, q] = pairs[static_cast<std::size_t>(k)];
    factored[static_cast<std::size_t>(k)] =
        build_gap(system, map, force_scale, at, centres.col(p), centres.col(q),
                  built[static_cast<std::size_t>(k)])
            ? 1
            : 0;
  }
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    if (built[k].dofs.empty()) continue;  // no polymer node between them
    if (factored[k] == 0) {
      ++left_out_;  // not positive definite (header)
      continue;
    }
    gaps_.push_back(std::move(built[k]));
  }
}

bool ContactGapBlocks::build_gap(const MessSystem& system, const DofMap& map, double force_scale,
                                 const Eigen::Matrix3Xd& at, const Eigen::Vector3d& first,
                                 const Eigen::Vector3d& second, Gap& gap) {
  const lattice::Lattice& lat = system.lattice();
  const std::vector<std::int64_t> nodes = gap_nodes(system, map, at, first, second);
  if (nodes.empty()) return false;
  std::vector<std::int32_t> local(static_cast<std::size_t>(lat.node_count()), -1);
  for (std::size_t k = 0; k < nodes.size(); ++k) {
    local[static_cast<std::size_t>(nodes[k])] = static_cast<std::int32_t>(k);
    for (int a = 0; a < 3; ++a) gap.dofs.push_back(map.own_dof_of_coordinate(3 * nodes[k] + a));
  }
  Eigen::SparseMatrix<float> lower;
  {
    GapSink sink(lat.shape, local, nodes.size(), lat.element_length / force_scale);
    system.add_elastic_hessian_blocks(sink, at);
    lower = sink.lower_matrix(nodes);
  }
  gap.factor = std::make_unique<Eigen::SimplicialLLT<Eigen::SparseMatrix<float>>>(lower);
  if (gap.factor->info() != Eigen::Success) return false;
  gap.solves = detail::SplitCholeskySolve(gap.factor->matrixL().nestedExpression());
  return true;
}

void ContactGapBlocks::add_to(const Eigen::VectorXd& v, Eigen::VectorXd& w) const {
  for (const Gap& gap : gaps_) {
    // H_g^-1 = P^T L^-T L^-1 P with the factor's L (single precision, its diagonal first in
    // each column) and fill-reducing permutation P; the solves in double, so that the operator
    // is symmetric to double rounding.
    const auto size = static_cast<Eigen::Index>(gap.dofs.size());
    Eigen::VectorXd r(size);
    for (Eigen::Index k = 0; k < size; ++k) r[k] = v[gap.dofs[static_cast<std::size_t>(k)]];
    Eigen::VectorXd y = gap.factor->permutationP() * r;
    gap.solves.solve(gap.factor->matrixL().nestedExpression(), y);
    const Eigen::VectorXd x = gap.factor->permutationP().transpose() * y;
    for (Eigen::Index k = 0; k < size; ++k) w[gap.dofs[static_cast<std::size_t>(k)]] += x[k];
  }
}

Eigen::Index ContactGapBlocks::dofs() const {
  Eigen::Index count = 0;
  for (const Gap& gap : gaps_) count += static_cast<Eigen::Index>(gap.dofs.size());
  return count;
}

}  // namespace mresim::mess
