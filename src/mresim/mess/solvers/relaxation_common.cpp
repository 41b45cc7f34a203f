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
  double m = 0.0;
  const Eigen::VectorXd reduced = map_.reduce(gradient) / map_.length_scale();
  if (reduced.size() > 0) m = reduced.cwiseAbs().maxCoeff();
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
  last_ = distributed_ != nullptr ? distributed_->evaluate(system_, &gradient_)
                                  : system_.evaluate(&gradient_);
  ++evaluations_;
  const bool loaded = load_.size() != 0;
  if (loaded) gradient_ += load_;
  gradient = map_.reduce(gradient_) / e0_;
  return last_.potential / e0_ + (loaded ? load_reduced_.dot(u - load_origin_) : 0.0);
}

void Objective::set_load(const Eigen::Matrix3Xd& load, const Eigen::VectorXd& u_ref) {
  load_ = load;
  load_reduced_ = map_.reduce(load) / e0_;
  load_origin_ = u_ref;
}

void Objective::clear_load() {
  load_.resize(3, 0);
  load_reduced_.resize(0);
  load_origin_.resize(0);
}

}  // namespace mresim::mess::detail
