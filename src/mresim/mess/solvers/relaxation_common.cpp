#include "mresim/mess/solvers/relaxation_common.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "mresim/mess/distributed/distributed_evaluator.hpp"

namespace mresim::mess::detail {

double characteristic_mass(const lattice::Lattice& lat) {
  const auto& shape = lat.shape;
  for (std::int64_t n = 0; n < lat.node_count(); ++n) {
    if (!lat.particle_of_node.empty() && lat.particle_of_node[static_cast<std::size_t>(n)] >= 0) {
      continue;
    }
    const auto c = shape.node_coordinates(static_cast<int>(n));
    int cells = 1;  // cells at the node: 2 per axis inside, 1 on a face of that axis
    for (int a = 0; a < 3; ++a) cells *= (c[a] == 0 || c[a] == shape.nodes[a] - 1) ? 1 : 2;
    return lat.masses[n] * 8.0 / cells;
  }
  throw std::invalid_argument("characteristic_mass: the lattice has no polymer node");
}

ForceMeasure::ForceMeasure(const MessSystem& system, const DofMap& map)
    : map_(map), particles_(system.lattice().particle_nodes), fixed_(system.constraints().fixed) {}

double ForceMeasure::max_force(const Eigen::Matrix3Xd& gradient) const {
  double m = map_.max_abs_reduced_divided(gradient, map_.length_scale());
  for (const auto& nodes : particles_) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (const std::int32_t n : nodes) {
      for (int a = 0; a < 3; ++a) {
        if (fixed_.empty() || fixed_[3 * static_cast<std::size_t>(n) + a] == 0) {
          sum[a] += gradient(a, n);
        }
      }
    }
    m = std::max(m, sum.cwiseAbs().maxCoeff());
  }
  return m;
}

Objective::Objective(MessSystem& system, const DofMap& map, double force_scale,
                     DistributedEvaluator* distributed)
    : system_(system),
      map_(map),
      e0_(force_scale * map.length_scale()),
      distributed_(distributed) {}

double Objective::operator()(const Eigen::VectorXd& u, Eigen::VectorXd& gradient) {
  map_.to_positions(u, system_.mutable_positions());
  return evaluate_here(u, gradient);
}

double Objective::along(const Eigen::VectorXd& u, double alpha, const Eigen::VectorXd& d,
                        Eigen::VectorXd& gradient) {
  map_.to_positions(u, alpha, d, system_.mutable_positions());
  return evaluate_here(u + alpha * d, gradient);
}

template <class Dofs>
double Objective::evaluate_here(const Dofs& u, Eigen::VectorXd& gradient) {
  last_ = distributed_ != nullptr ? distributed_->evaluate(system_, &gradient_)
                                  : system_.evaluate(&gradient_);
  ++evaluations_;
  if (loaded_) {
    for (std::size_t k = 0; k < load_nodes_.size(); ++k) {
      gradient_.col(load_nodes_[k]) += load_columns_.col(static_cast<Eigen::Index>(k));
    }
  }
  map_.reduce_divided(gradient_, e0_, gradient);
  if (!loaded_) return last_.potential / e0_;
  double load_work = 0.0;  // load . (u - u_ref), over the load's nonzero components in order
  for (const ReducedLoad& l : load_reduced_) load_work += l.value * (u.coeff(l.dof) - l.origin);
  return last_.potential / e0_ + load_work;
}

void Objective::set_load(const Eigen::Matrix3Xd& load, const Eigen::VectorXd& u_ref) {
  // The seed's correction load lives on the particle nodes only (elsewhere both centre rules
  // give the same gradient bit for bit), so only its nonzero columns are kept.
  load_nodes_.clear();
  for (Eigen::Index n = 0; n < load.cols(); ++n) {
    if (!load.col(n).isZero(0.0)) load_nodes_.push_back(static_cast<std::int32_t>(n));
  }
  load_columns_.resize(3, static_cast<Eigen::Index>(load_nodes_.size()));
  for (std::size_t k = 0; k < load_nodes_.size(); ++k) {
    load_columns_.col(static_cast<Eigen::Index>(k)) = load.col(load_nodes_[k]);
  }
  Eigen::VectorXd reduced;  // for the moment of this call only
  map_.reduce_divided(load, e0_, reduced);
  load_reduced_.clear();
  for (Eigen::Index k = 0; k < reduced.size(); ++k) {
    if (reduced[k] != 0.0) load_reduced_.push_back({k, reduced[k], u_ref[k]});
  }
  loaded_ = true;
}

void Objective::clear_load() {
  load_nodes_.clear();
  load_columns_.resize(3, 0);
  load_reduced_.clear();
  loaded_ = false;
}

}  // namespace mresim::mess::detail
