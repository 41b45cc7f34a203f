#include "mresim/mess/solvers/preconditioner.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <Eigen/QR>
#include <cmath>
#include <stdexcept>

#include "mresim/mess/solvers/stiffness_terms.hpp"
#include "mresim/mess/solvers/vector_algebra.hpp"

namespace mresim::mess {

RigidParticlePreconditioner::RigidParticlePreconditioner(
    const MessSystem& system, const DofMap& map, double force_scale, bool multilevel,
    const Eigen::Matrix3Xd* state, const detail::BlockSplit* processes, NodeScaling node_scaling,
    ContactGap contact_gap) {
  const lattice::Lattice& lat = system.lattice();
  // Where the particles' rigid motions are taken: the state, or the reference lattice.
  const Eigen::Matrix3Xd& x = state != nullptr ? *state : lat.positions;
  const double l_e = lat.element_length;
  const double volume_force_factor = system.settings().elastic.volume_force_factor;
  // Hessian diagonal per node coordinate (N/m) of the stiffness terms (stiffness_terms.hpp), and
  // where the node blocks are asked for, each node block's off-diagonal entries (xy, xz, yz).
  Eigen::Matrix3Xd d = Eigen::Matrix3Xd::Zero(3, lat.node_count());
  const bool blocks = state != nullptr && node_scaling == NodeScaling::blocks;
  Eigen::Matrix3Xd off = Eigen::Matrix3Xd::Zero(3, blocks ? lat.node_count() : 0);
  const auto add_off_diagonal = [&off](std::int64_t n, const Eigen::Vector3d& u, double c) {
    off.col(n) += c * Eigen::Vector3d(u.x() * u.y(), u.x() * u.z(), u.y() * u.z());
  };
  // At rest the cells' diagonal is the one constant below (kept as it always was computed, so
  // that a preconditioner built at rest has the same bits as before the states existed).
  const double cell_at_rest = volume_force_factor * std::abs(lat.polymer.kappa) * l_e / 16.0;
  for_each_stiffness_term(
      lat, state, map, volume_force_factor, 1.0,
      [&](std::int64_t i, std::int64_t j, const Eigen::Vector3d& u, double c) {
        const Eigen::Vector3d h = c * u.cwiseAbs2();
        d.col(i) += h;
        d.col(j) += h;
        if (blocks) {
          add_off_diagonal(i, u, c);
          add_off_diagonal(j, u, c);
        }
      },
      [&](const auto& element, const lattice::CellVertices& g, double c) {
        for (std::size_t v = 0; v < 8; ++v) {
          if (state == nullptr) {
            d.col(element[v]).array() += cell_at_rest;
          } else {
            d.col(element[v]) += c * g[v].cwiseAbs2();
            if (blocks) add_off_diagonal(element[v], g[v], c);
          }
        }
      });

  // Per dof (group dofs: sum over the group's nodes), scaled.
  const double scale = l_e / force_scale;
  Eigen::VectorXd diagonal = Eigen::VectorXd::Zero(map.size());
  double polymer_sum = 0.0;
  std::int64_t polymer_count = 0;
  for (std::int64_t n = 0; n < lat.node_count(); ++n) {
    const bool particle =
        !lat.particle_of_node.empty() && lat.particle_of_node[static_cast<std::size_t>(n)] >= 0;
    for (int a = 0; a < 3; ++a) {
      const Eigen::Index k = map.dof_of(n, a);
      if (k < 0) continue;
      diagonal[k] += d(a, n) * scale;
      if (!particle) {
        polymer_sum += d(a, n) * scale;
        ++polymer_count;
      }
    }
  }
  for (Eigen::Index k = 0; k < diagonal.size(); ++k) {
    if (!(diagonal[k] > 0.0)) diagonal[k] = 1.0;
  }
  inverse_diagonal_ = diagonal.cwiseInverse();
  diagonal.resize(0);
  if (blocks) invert_node_blocks(lat, map, d, off, scale);
  // Released before the gaps and the coarse levels are built (72 bytes per node with these).
  d.resize(3, 0);
  off.resize(3, 0);
  rigid_stiffness_ = polymer_count > 0 ? polymer_sum / static_cast<double>(polymer_count) : 1.0;

  add_particle_blocks(lat, map, x);
  if (state != nullptr && contact_gap == ContactGap::exact) {
    auto gaps = std::make_unique<ContactGapBlocks>(system, map, force_scale, *state);
    if (gaps->gaps() > 0) contact_gaps_ = std::move(gaps);
  }
  if (multilevel) {
    try {
      multilevel_ = std::make_unique<MultilevelCorrection>(
          lat, volume_force_factor, map, force_scale, state,
          MultilevelCorrection::kDefaultExactLimit, processes);
    } catch (const std::runtime_error&) {
      multilevel_.reset();  // nothing held: the coarse Hessian is singular (header)
    }
  }
}

void RigidParticlePreconditioner::add_particle_blocks(const lattice::Lattice& lat,
                                                      const DofMap& map,
                                                      const Eigen::Matrix3Xd& x) {
  const double l_e = lat.element_length;
  // The particles whose coordinates are all plain free dofs.
  for (const auto& nodes : lat.particle_nodes) {
    Block b;
    bool free = true;
    for (const std::int32_t n : nodes) {
      for (int a = 0; a < 3; ++a) {
        const Eigen::Index k = map.dof_of(n, a);
        if (k < 0 || map.is_group_dof(k)) free = false;
        b.dofs.push_back(k);
      }
    }
    if (!free) continue;
    const auto np = static_cast<Eigen::Index>(nodes.size());
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    for (const std::int32_t n : nodes) centre += x.col(n);
    centre /= static_cast<double>(np);
    Eigen::MatrixXd r = Eigen::MatrixXd::Zero(3 * np, 6);
    for (Eigen::Index i = 0; i < np; ++i) {
      const Eigen::Vector3d p = (x.col(nodes[static_cast<std::size_t>(i)]) - centre) / l_e;
      r.block<3, 3>(3 * i, 0).setIdentity();
      // Rotation about axis c: omega_c x p.
      r.block<3, 1>(3 * i, 3) = Eigen::Vector3d::UnitX().cross(p);
      r.block<3, 1>(3 * i, 4) = Eigen::Vector3d::UnitY().cross(p);
      r.block<3, 1>(3 * i, 5) = Eigen::Vector3d::UnitZ().cross(p);
    }
    b.q = Eigen::HouseholderQR<Eigen::MatrixXd>(r).householderQ() *
          Eigen::MatrixXd::Identity(3 * np, 6);
    blocks_.push_back(std::move(b));
  }
}

void RigidParticlePreconditioner::invert_node_blocks(const lattice::Lattice& lat, const DofMap& map,
                                                     const Eigen::Matrix3Xd& diagonal,
                                                     const Eigen::Matrix3Xd& off, double scale) {
  // Each node's block is inverted on its own (both threads), then the blocks taken are listed in
  // node order: the same list for any number of threads.
  const std::int64_t nodes = lat.node_count();
  std::vector<NodeBlock> all(static_cast<std::size_t>(nodes));
  std::vector<char> taken(static_cast<std::size_t>(nodes), 0);
#pragma omp parallel for schedule(static) if (nodes >= detail::kParallelMinimum)
  for (std::int64_t n = 0; n < nodes; ++n) {
    if (!lat.particle_of_node.empty() && lat.particle_of_node[static_cast<std::size_t>(n)] >= 0) {
      continue;  // the particles' blocks (their rigid motions) take these dofs
    }
    const Eigen::Index first = map.dof_of(n, 0);
    if (first < 0 || map.dof_of(n, 1) != first + 1 || map.dof_of(n, 2) != first + 2 ||
        map.is_group_dof(first)) {
      continue;
    }
    Eigen::Matrix3d b;
    b.diagonal() = diagonal.col(n);
    b(0, 1) = b(1, 0) = off(0, n);
    b(0, 2) = b(2, 0) = off(1, n);
    b(1, 2) = b(2, 1) = off(2, n);
    b *= scale;
    const Eigen::LLT<Eigen::Matrix3d> factor(b);
    const Eigen::Vector3d root_pivots = factor.matrixLLT().diagonal();
    if (factor.info() != Eigen::Success || !(root_pivots.minCoeff() > 0.0) ||
        root_pivots.minCoeff() * root_pivots.minCoeff() < 1e-8 * b.diagonal().maxCoeff()) {
      continue;  // not safely positive definite: the diagonal
    }
    const Eigen::Matrix3d inverse = factor.solve(Eigen::Matrix3d::Identity());
    for (int a = 0; a < 3; ++a) inverse_diagonal_[first + a] = inverse(a, a);
    all[static_cast<std::size_t>(n)] = {first, 0.5 * (inverse(0, 1) + inverse(1, 0)),
                                        0.5 * (inverse(0, 2) + inverse(2, 0)),
                                        0.5 * (inverse(1, 2) + inverse(2, 1))};
    taken[static_cast<std::size_t>(n)] = 1;
  }
  for (std::size_t n = 0; n < all.size(); ++n) {
    if (taken[n] != 0) node_blocks_.push_back(all[n]);
  }
}

Eigen::VectorXd RigidParticlePreconditioner::apply(const DofMap& map,
                                                   const Eigen::VectorXd& v) const {
  Eigen::VectorXd w;
  detail::parallel_product(inverse_diagonal_, v, w);  // both cores: a million dofs at full size
  // The node blocks' off-diagonal entries; each block writes only its own node's entries.
  const auto block_count = static_cast<std::int64_t>(node_blocks_.size());
#pragma omp parallel for schedule(static) if (block_count >= detail::kParallelMinimum)
  for (std::int64_t i = 0; i < block_count; ++i) {
    const NodeBlock& b = node_blocks_[static_cast<std::size_t>(i)];
    const double x = v[b.first];
    const double y = v[b.first + 1];
    const double z = v[b.first + 2];
    w[b.first] += b.xy * y + b.xz * z;
    w[b.first + 1] += b.xy * x + b.yz * z;
    w[b.first + 2] += b.xz * x + b.yz * y;
  }
  for (const Block& b : blocks_) {
    const auto m = static_cast<Eigen::Index>(b.dofs.size());
    Eigen::VectorXd vp(m);
    for (Eigen::Index i = 0; i < m; ++i) vp[i] = v[b.dofs[static_cast<std::size_t>(i)]];
    const Eigen::VectorXd t = b.q.transpose() * vp;
    Eigen::VectorXd internal = vp - b.q * t;
    for (Eigen::Index i = 0; i < m; ++i)
      internal[i] *= inverse_diagonal_[b.dofs[static_cast<std::size_t>(i)]];
    internal -= b.q * (b.q.transpose() * internal);
    const Eigen::VectorXd wp = internal + b.q * (t / rigid_stiffness_);
    for (Eigen::Index i = 0; i < m; ++i) w[b.dofs[static_cast<std::size_t>(i)]] = wp[i];
  }
  if (multilevel_ != nullptr) multilevel_->add_to(map, v, w);
  if (contact_gaps_ != nullptr) contact_gaps_->add_to(v, w);
  return w;
}

}  // namespace mresim::mess
