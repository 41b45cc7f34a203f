#include "mresim/mess/solvers/newton.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace mresim::mess::detail {

NewtonSolver::NewtonSolver(MessSystem& system, const DofMap& map, double force_scale,
                           const NewtonOptions& options)
    : system_(system), map_(map), force_scale_(force_scale), options_(options) {
  if (system.settings().centre_rule != CentreRule::all_nodes) {
    throw std::logic_error("NewtonSolver: needs CentreRule::all_nodes (an exact gradient)");
  }
  build_preconditioner();
}

void NewtonSolver::build_preconditioner() {
  const auto start = std::chrono::steady_clock::now();
  const double l_e = map_.length_scale();
  matrix_ = std::make_unique<ElasticMatrix>(system_.lattice());
  // Scaled like the free variables: H_u = l_e H_x / F0.
  matrix_->assemble(system_, map_.own_dof_mask(), l_e / force_scale_);
  const Eigen::Matrix3Xd coordinates = system_.positions() / l_e;
  amg_ = std::make_unique<AmgPreconditioner>(*matrix_, coordinates, options_.amg);
  // The rigid groups' translations: their diagonal of H (M's dependence left out).
  const Eigen::Index own = map_.own_dofs();
  group_diagonal_.resize(3 * map_.groups());
  centre_hessian_ = Eigen::MatrixXd::Zero(3 * static_cast<Eigen::Index>(system_.particle_count()),
                                          3 * static_cast<Eigen::Index>(system_.particle_count()));
  for (Eigen::Index k = 0; k < group_diagonal_.size(); ++k) {
    Eigen::VectorXd unit = Eigen::VectorXd::Zero(map_.size());
    unit[own + k] = 1.0;
    group_diagonal_[k] = std::max(hessian_product(unit)[own + k], 1e-300);
  }
  setup_seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

Eigen::VectorXd NewtonSolver::hessian_product(const Eigen::VectorXd& v) const {
  const Eigen::Matrix3Xd w = map_.expand(v);
  Eigen::Matrix3Xd y = system_.elastic_hessian_product(w);
  const auto& particles = system_.lattice().particle_nodes;
  const auto np = static_cast<Eigen::Index>(particles.size());
  if (np > 0 && centre_hessian_.size() > 0) {
    // S w: each centre moves by the mean of its nodes' directions (CentreRule::all_nodes).
    Eigen::VectorXd wc(3 * np);
    for (Eigen::Index p = 0; p < np; ++p) {
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      for (const std::int32_t n : particles[static_cast<std::size_t>(p)]) sum += w.col(n);
      wc.segment<3>(3 * p) =
          sum / static_cast<double>(particles[static_cast<std::size_t>(p)].size());
    }
    const Eigen::VectorXd yc = centre_hessian_ * wc;
    // S^T: spread as 1/n_p to each node, as the centre forces are (system_energy.hpp).
    for (Eigen::Index p = 0; p < np; ++p) {
      const auto& nodes = particles[static_cast<std::size_t>(p)];
      const Eigen::Vector3d share = yc.segment<3>(3 * p) / static_cast<double>(nodes.size());
      for (const std::int32_t n : nodes) y.col(n) += share;
    }
  }
  return map_.reduce(y) / force_scale_;
}

Eigen::VectorXd NewtonSolver::precondition(const Eigen::VectorXd& r) const {
  const Eigen::Index own = map_.own_dofs();
  Eigen::VectorXd nodes = Eigen::VectorXd::Zero(matrix_->rows());
  for (Eigen::Index k = 0; k < own; ++k) nodes[map_.coordinate_of(k)] = r[k];
  Eigen::VectorXd z_nodes;
  amg_->apply(nodes, z_nodes);
  Eigen::VectorXd z(r.size());
  for (Eigen::Index k = 0; k < own; ++k) z[k] = z_nodes[map_.coordinate_of(k)];
  z.tail(group_diagonal_.size()) = r.tail(group_diagonal_.size()).cwiseQuotient(group_diagonal_);
  return z;
}

Eigen::VectorXd NewtonSolver::newton_direction(const Eigen::VectorXd& g, double eta) {
  Eigen::VectorXd x = Eigen::VectorXd::Zero(g.size());
  Eigen::VectorXd r = -g;
  Eigen::VectorXd z = precondition(r);
  Eigen::VectorXd p = z;
  double rz = r.dot(z);
  const double target = eta * g.norm();
  for (int k = 0; k < options_.max_krylov_iterations; ++k) {
    const Eigen::VectorXd hp = hessian_product(p);
    ++krylov_iterations_;
    const double curvature = p.dot(hp);
    if (!(curvature > 0.0)) {
      // Negative curvature: the iterate so far, or the preconditioned steepest descent.
      return k == 0 ? p : x;
    }
    const double alpha = rz / curvature;
    x += alpha * p;
    r -= alpha * hp;
    if (r.norm() <= target) break;
    z = precondition(r);
    const double rz_next = r.dot(z);
    p = z + (rz_next / rz) * p;
    rz = rz_next;
  }
  return x;
}

InnerResult NewtonSolver::run(Objective& f, Eigen::VectorXd& u, int budget,
                              const MinimiserOptions& options, bool use_energy,
                              const ConvergenceTest& converged) {
  InnerResult r;
  LinePoint cur;
  cur.phi = f(u, cur.g);
  if (!std::isfinite(cur.phi)) {
    r.status = MinimiserStatus::not_finite;
    return r;
  }
  if (converged(cur.g, 0.0)) {
    r.status = MinimiserStatus::converged;
    return r;
  }
  constexpr int kStallIterations = 20;
  int stalled = 0;
  int failures = 0;
  double best_gradient = cur.g.cwiseAbs().maxCoeff();
  while (r.iterations < budget) {
    update_centre_hessian();
    const double gmax = cur.g.cwiseAbs().maxCoeff();
    // After a failed line search: one preconditioned steepest-descent step.
    Eigen::VectorXd d =
        failures > 0 ? Eigen::VectorXd(-precondition(cur.g))
                     : newton_direction(cur.g, std::min(options_.forcing_max, std::sqrt(gmax)));
    cur.dphi = cur.g.dot(d);
    if (!(cur.dphi < 0.0)) {
      d = -precondition(cur.g);
      cur.dphi = cur.g.dot(d);
    }
    const double alpha_max = options.max_step / d.cwiseAbs().maxCoeff();
    LinePoint next;
    const bool ok = wolfe_line_search(f, u, d, cur, 1.0, alpha_max, use_energy, next);
    ++r.iterations;
    if (!ok) {
      if (++failures >= 2) {
        r.status = MinimiserStatus::line_search_failed;
        return r;
      }
      continue;
    }
    failures = 0;
    u += next.alpha * d;
    r.energy_change = next.phi - cur.phi;
    cur = std::move(next);
    const double g_next = cur.g.cwiseAbs().maxCoeff();
    const double noise = 64.0 * std::numeric_limits<double>::epsilon() * f.magnitude();
    if (g_next < best_gradient || (use_energy && r.energy_change < -noise)) {
      best_gradient = std::min(best_gradient, g_next);
      stalled = 0;
    } else if (++stalled >= kStallIterations) {
      r.status = MinimiserStatus::stalled;
      return r;
    }
    if (converged(cur.g, r.energy_change)) {
      r.status = MinimiserStatus::converged;
      return r;
    }
  }
  return r;
}

}  // namespace mresim::mess::detail
