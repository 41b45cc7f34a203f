#include "mresim/mess/solvers/newton.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "mresim/mess/solvers/vector_algebra.hpp"

namespace mresim::mess::detail {

namespace {

// Adds the wall time of its lifetime to `total`.
class Stopwatch {
 public:
  explicit Stopwatch(double& total) : total_(total), start_(std::chrono::steady_clock::now()) {}
  Stopwatch(const Stopwatch&) = delete;
  Stopwatch& operator=(const Stopwatch&) = delete;
  Stopwatch(Stopwatch&&) = delete;
  Stopwatch& operator=(Stopwatch&&) = delete;
  ~Stopwatch() {
    total_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }

 private:
  double& total_;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace

NewtonSolver::NewtonSolver(MessSystem& system, const DofMap& map, double force_scale,
                           const NewtonOptions& options, std::shared_ptr<NewtonCache> cache)
    : system_(system),
      map_(map),
      force_scale_(force_scale),
      options_(options),
      centre_hessian_(
          Eigen::MatrixXd::Zero(3 * static_cast<Eigen::Index>(system.particle_count()),
                                3 * static_cast<Eigen::Index>(system.particle_count()))),
      cache_(cache != nullptr ? std::move(cache) : std::make_shared<NewtonCache>()) {
  const std::vector<std::uint8_t> own = map_.own_dof_mask();
  NewtonPreconditioner* kept = cache_->current.get();
  if (kept != nullptr && !kept->stale && kept->own_dofs == own &&
      kept->group_diagonal.size() == 3 * map_.groups()) {
    pc_ = kept;
  } else {
    build_preconditioner();
  }
}

void NewtonSolver::build_preconditioner() {
  const auto start = std::chrono::steady_clock::now();
  const double l_e = map_.length_scale();
  auto pc = std::make_unique<NewtonPreconditioner>();
  pc->own_dofs = map_.own_dof_mask();
  pc->matrix = std::make_unique<ElasticMatrix>(system_.lattice());
  // Scaled like the free variables: H_u = l_e H_x / F0.
  pc->matrix->assemble(system_, pc->own_dofs, l_e / force_scale_);
  const Eigen::Matrix3Xd coordinates = system_.positions() / l_e;
  pc->amg = std::make_unique<AmgPreconditioner>(*pc->matrix, coordinates, options_.amg);
  cache_->current = std::move(pc);
  ++cache_->setups;
  pc_ = cache_->current.get();
  // The rigid groups' translations: their diagonal of H (M's dependence left out).
  const Eigen::Index own = map_.own_dofs();
  pc_->group_diagonal = Eigen::VectorXd::Ones(3 * map_.groups());
  for (Eigen::Index k = 0; k < pc_->group_diagonal.size(); ++k) {
    Eigen::VectorXd unit = Eigen::VectorXd::Zero(map_.size());
    unit[own + k] = 1.0;
    pc_->group_diagonal[k] = std::max(hessian_product(unit)[own + k], 1e-300);
  }
  setup_seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void NewtonSolver::note_convergence(int iterations, double reduction) {
  // A one-iteration solve or no reduction says nothing about the preconditioner.
  if (iterations < 2 || !(reduction > 0.0 && reduction < 1.0)) return;
  const double per_decade = static_cast<double>(iterations) / -std::log10(reduction);
  // The reference is the slowest of the first solves after the build: the very first is often
  // faster than what the multigrid does later at the same place (a small first step). Measured
  // on the small Fig. 4.11 pair (docs/mess-solvers.md): 5-16 iterations per decade with a fresh
  // multigrid, 20-60 once the pair has snapped into contact with the one built before, where a
  // rebuild (about 20-40 iterations' cost) pays off within a Newton step or two.
  constexpr int kReferenceSolves = 3;
  constexpr double kSlack = 2.0;
  NewtonPreconditioner& pc = *pc_;
  if (pc.reference_solves < kReferenceSolves) {
    pc.fresh_iterations_per_decade = std::max(pc.fresh_iterations_per_decade, per_decade);
    ++pc.reference_solves;
    return;
  }
  const double slowdown = options_.multigrid_rebuild_slowdown;
  if (slowdown > 0.0 && per_decade > slowdown * pc.fresh_iterations_per_decade + kSlack) {
    pc.stale = true;
  }
}

void NewtonSolver::update_centre_hessian() {
  {
    const Stopwatch watch(timings_.centre_hessian);
    centre_hessian_ = system_.reduced_centre_hessian();
  }
  update_woodbury();
}

Eigen::VectorXd NewtonSolver::hessian_product(const Eigen::VectorXd& v) const {
  const Stopwatch watch(timings_.products);
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
  Eigen::VectorXd z = elastic_precondition(r);
  if (woodbury_w_.cols() == 0) return z;
  // Woodbury: (A + U K U^T)^-1 ~ B - B U (I + K U^T B U)^-1 K U^T B, B the V-cycle.
  const Eigen::VectorXd uz = centre_directions_.transpose() * z;
  z -= woodbury_w_ * woodbury_c_.solve(centre_stiffness_ * uz);
  return z;
}

void NewtonSolver::update_woodbury() {
  const Eigen::Index columns = centre_hessian_.cols();
  woodbury_w_.resize(0, 0);
  if (columns == 0) return;
  if (centre_directions_.cols() != columns) {
    // U: column (p, a) = reduce() of a unit centre force spread as 1/n_p over the particle's
    // nodes, so that H's centre part is U K' U^T with K' = K_c / (F0 l_e).
    centre_directions_ = Eigen::MatrixXd::Zero(map_.size(), columns);
    const auto& particles = system_.lattice().particle_nodes;
    for (Eigen::Index c = 0; c < columns; ++c) {
      Eigen::Matrix3Xd spread = Eigen::Matrix3Xd::Zero(3, system_.node_count());
      const auto& nodes = particles[static_cast<std::size_t>(c / 3)];
      for (const std::int32_t n : nodes) {
        spread(c % 3, n) = 1.0 / static_cast<double>(nodes.size());
      }
      centre_directions_.col(c) = map_.reduce(spread);
    }
  }
  // Only K's positive part (the stiff contact), so that the preconditioner stays positive
  // definite where the attraction makes H indefinite.
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(centre_hessian_ /
                                                             (force_scale_ * map_.length_scale()));
  const Eigen::VectorXd positive = eigen.eigenvalues().cwiseMax(0.0);
  if (!(positive.maxCoeff() > 0.0)) return;
  centre_stiffness_ =
      eigen.eigenvectors() * positive.asDiagonal() * eigen.eigenvectors().transpose();
  woodbury_w_.resize(map_.size(), columns);
  for (Eigen::Index c = 0; c < columns; ++c) {
    woodbury_w_.col(c) = elastic_precondition(centre_directions_.col(c));
  }
  woodbury_c_.compute(Eigen::MatrixXd::Identity(columns, columns) +
                      centre_stiffness_ * (centre_directions_.transpose() * woodbury_w_));
}

Eigen::VectorXd NewtonSolver::elastic_precondition(const Eigen::VectorXd& r) const {
  const Eigen::Index own = map_.own_dofs();
  Eigen::VectorXd nodes = Eigen::VectorXd::Zero(pc_->matrix->rows());
  for (Eigen::Index k = 0; k < own; ++k) nodes[map_.coordinate_of(k)] = r[k];
  Eigen::VectorXd z_nodes;
  {
    const Stopwatch watch(timings_.multigrid);
    pc_->amg->apply(nodes, z_nodes);
  }
  Eigen::VectorXd z(r.size());
  for (Eigen::Index k = 0; k < own; ++k) z[k] = z_nodes[map_.coordinate_of(k)];
  const Eigen::Index groups = pc_->group_diagonal.size();
  z.tail(groups) = r.tail(groups).cwiseQuotient(pc_->group_diagonal);
  return z;
}

namespace {

// The largest tau >= 0 with |x + tau p|_inf <= radius, for x inside that box.
double distance_to_boundary(const Eigen::VectorXd& x, const Eigen::VectorXd& p, double radius) {
  double tau = std::numeric_limits<double>::infinity();
  for (Eigen::Index i = 0; i < x.size(); ++i) {
    if (p[i] > 0.0) {
      tau = std::min(tau, (radius - x[i]) / p[i]);
    } else if (p[i] < 0.0) {
      tau = std::min(tau, (-radius - x[i]) / p[i]);
    }
  }
  return std::max(tau, 0.0);
}

}  // namespace

NewtonDirection NewtonSolver::newton_direction(const Eigen::VectorXd& g, double eta,
                                               double radius) {
  // Vector algebra on both cores, independent of the thread count (vector_algebra.hpp).
  Eigen::VectorXd x = Eigen::VectorXd::Zero(g.size());
  Eigen::VectorXd r = -g;
  Eigen::VectorXd z = precondition(r);
  Eigen::VectorXd p = z;
  double rz = parallel_dot(r, z);
  const double g_norm = std::sqrt(parallel_dot(g, g));
  const double target = eta * g_norm;
  // Steihaug: leaving the box |x|_inf <= radius, or along a direction of non-positive
  // curvature, the step ends on the box's boundary.
  const auto to_boundary = [&]() {
    parallel_axpy(distance_to_boundary(x, p, radius), p, x);
    return NewtonDirection{std::move(x), true};
  };
  for (int k = 0; k < options_.max_krylov_iterations; ++k) {
    const Eigen::VectorXd hp = hessian_product(p);
    ++krylov_iterations_;
    const double curvature = parallel_dot(p, hp);
    if (!(curvature > 0.0)) return to_boundary();
    const double alpha = rz / curvature;
    if ((x + alpha * p).cwiseAbs().maxCoeff() > radius) return to_boundary();
    parallel_axpy(alpha, p, x);
    const double residual = std::sqrt(parallel_axpy_dot(-alpha, hp, r, r));
    if (residual <= target) {
      note_convergence(k + 1, residual / g_norm);
      break;
    }
    z = precondition(r);
    const double rz_next = parallel_dot(r, z);
    // p = z + beta p
    parallel_scale_add(rz_next / rz, z, p);
    rz = rz_next;
  }
  return {std::move(x), false};
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
  StallGuard guard(cur.g, kStallIterations);
  int failures = 0;
  // The largest coordinate change of a step (units of l_e), the trust radius of CG's path:
  // max_step at first, grown by half (up to kStepGrowth max_step) after a step that reached it
  // and was accepted whole, halved (down to kStepShrink max_step) after one the line search had
  // to shorten. A pair snapping into contact moves ~10 l_e, which steps of 0.2 l_e would take 50
  // Newton steps for; in contact, directions of negative curvature (the pair tilting off the
  // field axis by a few nm) need steps far below 0.2 l_e (with a floor of max_step, the small
  // Fig. 4.11 loop needed 3,145 CG iterations; with max_step/64, 2,269; docs/performance.md).
  constexpr double kStepGrowth = 16.0;
  constexpr double kStepShrink = 1.0 / 64.0;
  double step_cap = options.max_step;
  bool capped = false;  // the last step was cut short by the cap: its direction was far off
  while (r.iterations < budget) {
    if (pc_->stale) build_preconditioner();
    update_centre_hessian();
    const double gmax = cur.g.cwiseAbs().maxCoeff();
    // CG's relative residual: sqrt(|g|) for superlinear convergence, but no tighter than what
    // takes the forces to half the tolerance (the scaled gradient is in units of the force
    // scale, so the target is force_tolerance): the last step need not be solved to 1e-3.
    // While the steps are cut short by the cap, an accurate direction is wasted: 0.5.
    const double eta =
        capped ? 0.5
               : std::min(options_.forcing_max,
                          std::max(std::sqrt(gmax), 0.5 * options.force_tolerance / gmax));
    // After a failed line search: one preconditioned steepest-descent step.
    NewtonDirection direction = failures > 0 ? NewtonDirection{-precondition(cur.g), false}
                                             : newton_direction(cur.g, eta, step_cap);
    Eigen::VectorXd& d = direction.step;
    cur.dphi = cur.g.dot(d);
    if (!(cur.dphi < 0.0)) {
      d = -precondition(cur.g);
      direction.on_boundary = false;
      cur.dphi = cur.g.dot(d);
    }
    // A step on the boundary reaches the cap at alpha = 1 (up to rounding).
    const double alpha_max = direction.on_boundary ? 1.0 : step_cap / d.cwiseAbs().maxCoeff();
    LinePoint next;
    const bool ok = wolfe_line_search(f, u, d, cur, 1.0, alpha_max, use_energy, next);
    ++r.iterations;
    ++newton_steps_;
    if (!ok) {
      if (++failures >= 2) {
        r.status = MinimiserStatus::line_search_failed;
        return r;
      }
      continue;
    }
    failures = 0;
    capped = (direction.on_boundary || alpha_max < 1.0) && next.alpha >= std::min(1.0, alpha_max);
    if (capped) {
      step_cap = std::min(1.5 * step_cap, kStepGrowth * options.max_step);
    } else if (next.alpha < 0.5 * std::min(1.0, alpha_max)) {
      step_cap = std::max(0.5 * step_cap, kStepShrink * options.max_step);
    }
    u += next.alpha * d;
    r.energy_change = next.phi - cur.phi;
    cur = std::move(next);
    if (guard.stalled(cur.g, r.energy_change, f, use_energy)) {
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
