#include "mresim/mess/system/constraints.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "mresim/mess/system/fixed_order.hpp"

namespace mresim::mess {

BoundaryConstraints BoundaryConstraints::none(std::int64_t node_count) {
  BoundaryConstraints c;
  c.fixed.assign(static_cast<std::size_t>(3 * node_count), 0);
  return c;
}

void BoundaryConstraints::hold(std::int64_t node, int axis, double value) {
  const auto n = static_cast<std::size_t>(node);
  if (node < 0 || 3 * n + 2 >= fixed.size() || axis < 0 || axis > 2) {
    throw std::invalid_argument("BoundaryConstraints::hold: node " + std::to_string(node) +
                                " axis " + std::to_string(axis) + " out of range (" +
                                std::to_string(fixed.size() / 3) + " nodes)");
  }
  fixed[3 * n + static_cast<std::size_t>(axis)] = 1;
  prescribed_.try_emplace(static_cast<std::int32_t>(node), Eigen::Vector3d::Zero())
      .first->second[axis] = value;
}

void BoundaryConstraints::hold(std::int64_t node, const Eigen::Vector3d& position) {
  for (int a = 0; a < 3; ++a) hold(node, a, position[a]);
}

double BoundaryConstraints::prescribed(int axis, std::int64_t node) const {
  const auto entry = prescribed_.find(static_cast<std::int32_t>(node));
  return entry == prescribed_.end() ? 0.0 : entry->second[axis];
}

void BoundaryConstraints::fix_nodes(const std::vector<int>& nodes,
                                    const Eigen::Matrix3Xd& positions) {
  if (fixed.empty()) *this = none(positions.cols());
  for (const int n : nodes) {
    if (n < 0 || n >= positions.cols()) {
      throw std::invalid_argument("BoundaryConstraints::fix_nodes: node " + std::to_string(n) +
                                  " out of range");
    }
    hold(n, Eigen::Vector3d(positions.col(n)));
  }
}

void BoundaryConstraints::fix_face(const lattice::GridShape& shape, lattice::Face face,
                                   const Eigen::Matrix3Xd& positions) {
  fix_nodes(lattice::face_nodes(shape, face), positions);
}

void BoundaryConstraints::add_rigid_group(std::vector<std::int32_t> nodes) {
  rigid_groups.push_back(RigidGroup{std::move(nodes)});
}

void BoundaryConstraints::validate(std::int64_t node_count) const {
  if (!fixed.empty() && static_cast<std::int64_t>(fixed.size()) != 3 * node_count) {
    throw std::invalid_argument("BoundaryConstraints: 'fixed' must have 3 entries per node");
  }
  for (const auto& [node, value] : prescribed_) {
    if (node >= node_count) {
      throw std::invalid_argument("BoundaryConstraints: held node " + std::to_string(node) +
                                  " out of range (" + std::to_string(node_count) + " nodes)");
    }
  }
  std::vector<std::uint8_t> in_group(static_cast<std::size_t>(node_count), 0);
  for (std::size_t g = 0; g < rigid_groups.size(); ++g) {
    if (rigid_groups[g].nodes.empty()) {
      throw std::invalid_argument("BoundaryConstraints: rigid group " + std::to_string(g) +
                                  " is empty");
    }
    for (const std::int32_t n : rigid_groups[g].nodes) {
      if (n < 0 || n >= node_count) {
        throw std::invalid_argument("BoundaryConstraints: rigid group " + std::to_string(g) +
                                    " has node " + std::to_string(n) + " out of range");
      }
      if (in_group[static_cast<std::size_t>(n)]++ != 0) {
        throw std::invalid_argument("BoundaryConstraints: node " + std::to_string(n) +
                                    " is in more than one rigid group");
      }
      for (int a = 0; a < 3; ++a) {
        if (is_fixed(n, a)) {
          throw std::invalid_argument("BoundaryConstraints: node " + std::to_string(n) +
                                      " of rigid group " + std::to_string(g) +
                                      " has a held coordinate");
        }
      }
    }
  }
}

void BoundaryConstraints::apply(Eigen::Matrix3Xd& x) const {
  if (fixed.empty()) return;
  for (Eigen::Index n = 0; n < x.cols(); ++n) {
    for (int a = 0; a < 3; ++a) {
      if (fixed[static_cast<std::size_t>(3 * n + a)] != 0) x(a, n) = prescribed(a, n);
    }
  }
}

// ------------------------------------------------------------------------------- DofMap

DofMap::DofMap(const BoundaryConstraints& constraints, const Eigen::Matrix3Xd& reference,
               double length_scale)
    : length_scale_(length_scale) {
  const std::int64_t n_nodes = reference.cols();
  constraints.validate(n_nodes);
  std::vector<std::uint8_t> in_group(static_cast<std::size_t>(n_nodes), 0);
  for (const RigidGroup& g : constraints.rigid_groups) {
    Eigen::Matrix3Xd ref(3, static_cast<Eigen::Index>(g.nodes.size()));
    for (std::size_t k = 0; k < g.nodes.size(); ++k) {
      in_group[static_cast<std::size_t>(g.nodes[k])] = 1;
      ref.col(static_cast<Eigen::Index>(k)) = reference.col(g.nodes[k]);
    }
    group_nodes_.push_back(g.nodes);
    group_reference_.push_back(std::move(ref));
  }
  if (3 * n_nodes > std::numeric_limits<std::int32_t>::max()) {
    throw std::invalid_argument("DofMap: " + std::to_string(n_nodes) +
                                " nodes have more coordinates than 32-bit indices reach (at most " +
                                std::to_string(std::numeric_limits<std::int32_t>::max() / 3) +
                                " nodes)");
  }
  dof_index_.assign(static_cast<std::size_t>(3 * n_nodes), -1);
  for (std::int64_t n = 0; n < n_nodes; ++n) {
    if (in_group[static_cast<std::size_t>(n)] != 0) continue;
    for (int a = 0; a < 3; ++a) {
      if (constraints.is_fixed(n, a)) continue;
      dof_index_[static_cast<std::size_t>(3 * n + a)] =
          static_cast<std::int32_t>(coordinates_.size());
      coordinates_.push_back(static_cast<std::int32_t>(3 * n + a));
    }
  }
  const auto nc = static_cast<Eigen::Index>(coordinates_.size());
  for (std::size_t g = 0; g < group_nodes_.size(); ++g) {
    for (const std::int32_t n : group_nodes_[g]) {
      for (int a = 0; a < 3; ++a) {
        dof_index_[3 * static_cast<std::size_t>(n) + a] =
            static_cast<std::int32_t>(nc + 3 * static_cast<Eigen::Index>(g) + a);
      }
    }
  }
}

// The own dofs (one free coordinate each) are written elementwise, in the fixed blocks of
// detail::for_each_block, so that at full size (a million dofs) both cores share these passes
// with the same results as a serial loop; the rigid groups' few translations and sums over their
// nodes stay serial, in node order.

Eigen::VectorXd DofMap::to_dofs(const Eigen::Matrix3Xd& x) const {
  Eigen::VectorXd u(size());
  const double inv = 1.0 / length_scale_;
  const double* data = x.data();
  detail::for_each_block(own_dofs(), [&](std::int64_t begin, std::int64_t end) {
    for (std::int64_t k = begin; k < end; ++k) {
      u[k] = data[coordinates_[static_cast<std::size_t>(k)]] * inv;
    }
  });
  const Eigen::Index nc = own_dofs();
  for (Eigen::Index g = 0; g < groups(); ++g) {
    const auto gi = static_cast<std::size_t>(g);
    u.segment<3>(nc + 3 * g) = (x.col(group_nodes_[gi][0]) - group_reference_[gi].col(0)) * inv;
  }
  return u;
}

template <class Dofs>
void DofMap::write_positions(const Dofs& u, Eigen::Matrix3Xd& x) const {
  double* data = x.data();
  detail::for_each_block(own_dofs(), [&](std::int64_t begin, std::int64_t end) {
    for (std::int64_t k = begin; k < end; ++k) {
      data[coordinates_[static_cast<std::size_t>(k)]] = u[k] * length_scale_;
    }
  });
  const Eigen::Index nc = own_dofs();
  for (Eigen::Index g = 0; g < groups(); ++g) {
    const auto gi = static_cast<std::size_t>(g);
    const Eigen::Vector3d t = u.template segment<3>(nc + 3 * g) * length_scale_;
    for (std::size_t k = 0; k < group_nodes_[gi].size(); ++k) {
      x.col(group_nodes_[gi][k]) = group_reference_[gi].col(static_cast<Eigen::Index>(k)) + t;
    }
  }
}

void DofMap::to_positions(const Eigen::VectorXd& u, Eigen::Matrix3Xd& x) const {
  write_positions(u, x);
}

void DofMap::to_positions(const Eigen::VectorXd& u, double alpha, const Eigen::VectorXd& d,
                          Eigen::Matrix3Xd& x) const {
  write_positions(u + alpha * d, x);
}

template <class Visit>
void DofMap::for_each_reduced(const Eigen::Matrix3Xd& gradient, Visit&& visit) const {
  const double* data = gradient.data();
  detail::for_each_block(own_dofs(), [&](std::int64_t begin, std::int64_t end) {
    for (std::int64_t k = begin; k < end; ++k) {
      visit(k, data[coordinates_[static_cast<std::size_t>(k)]] * length_scale_);
    }
  });
  const Eigen::Index nc = own_dofs();
  for (Eigen::Index gr = 0; gr < groups(); ++gr) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (const std::int32_t n : group_nodes_[static_cast<std::size_t>(gr)]) sum += gradient.col(n);
    for (int a = 0; a < 3; ++a) visit(nc + 3 * gr + a, sum[a] * length_scale_);
  }
}

Eigen::VectorXd DofMap::reduce(const Eigen::Matrix3Xd& gradient) const {
  Eigen::VectorXd g(size());
  for_each_reduced(gradient, [&g](Eigen::Index k, double value) { g[k] = value; });
  return g;
}

void DofMap::reduce_divided(const Eigen::Matrix3Xd& gradient, double divisor,
                            Eigen::VectorXd& out) const {
  out.resize(size());
  for_each_reduced(gradient, [&](Eigen::Index k, double value) { out[k] = value / divisor; });
}

namespace {

// m = max(m, a), where a NaN stays: it must never pass a tolerance.
void keep_largest(double a, double& m) {
  if (a > m || std::isnan(a)) m = a;
}

}  // namespace

double DofMap::max_abs_reduced_divided(const Eigen::Matrix3Xd& gradient, double divisor) const {
  // One maximum per block of dofs (a group's three components count as the last block's),
  // then the largest of those: the maximum is exact in any order.
  const std::int64_t blocks = (size() + detail::kSumBlock - 1) / detail::kSumBlock;
  std::vector<double> largest(static_cast<std::size_t>(std::max<std::int64_t>(blocks, 1)), 0.0);
  for_each_reduced(gradient, [&](Eigen::Index k, double value) {
    keep_largest(std::abs(value / divisor),
                 largest[static_cast<std::size_t>(k / detail::kSumBlock)]);
  });
  double m = 0.0;
  for (const double a : largest) keep_largest(a, m);
  return m;
}

Eigen::Matrix3Xd DofMap::expand(const Eigen::VectorXd& v) const {
  Eigen::Matrix3Xd x = Eigen::Matrix3Xd::Zero(3, static_cast<Eigen::Index>(dof_index_.size() / 3));
  double* data = x.data();
  detail::for_each_block(own_dofs(), [&](std::int64_t begin, std::int64_t end) {
    for (std::int64_t k = begin; k < end; ++k)
      data[coordinates_[static_cast<std::size_t>(k)]] = v[k];
  });
  const Eigen::Index nc = own_dofs();
  for (Eigen::Index g = 0; g < groups(); ++g) {
    const Eigen::Vector3d t = v.segment<3>(nc + 3 * g);
    for (const std::int32_t n : group_nodes_[static_cast<std::size_t>(g)]) x.col(n) = t;
  }
  return x;
}

std::vector<std::uint8_t> DofMap::own_dof_mask() const {
  std::vector<std::uint8_t> mask(dof_index_.size(), 0);
  for (const std::int32_t c : coordinates_) mask[static_cast<std::size_t>(c)] = 1;
  return mask;
}

Eigen::VectorXd DofMap::reduce_masses(const Eigen::VectorXd& masses) const {
  Eigen::VectorXd m(size());
  const auto nc = static_cast<Eigen::Index>(coordinates_.size());
  for (Eigen::Index k = 0; k < nc; ++k)
    m[k] = masses[coordinates_[static_cast<std::size_t>(k)] / 3];
  for (Eigen::Index gr = 0; gr < groups(); ++gr) {
    double sum = 0.0;
    for (const std::int32_t n : group_nodes_[static_cast<std::size_t>(gr)]) sum += masses[n];
    m.segment<3>(nc + 3 * gr).setConstant(sum);
  }
  return m;
}

}  // namespace mresim::mess
