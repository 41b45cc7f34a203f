#include "mresim/mess/solvers/minimiser.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <random>
#include <stdexcept>

#include "mresim/mess/distributed/distributed_evaluator.hpp"
#include "mresim/mess/solvers/lbfgs_memory.hpp"
#include "mresim/mess/solvers/leapfrog.hpp"
#include "mresim/mess/solvers/line_search.hpp"
#include "mresim/mess/solvers/newton.hpp"
#include "mresim/mess/solvers/preconditioner_cache.hpp"
#include "mresim/mess/solvers/relaxation_common.hpp"
#include "mresim/mess/solvers/vector_algebra.hpp"

namespace mresim::mess {

std::string to_string(MinimiserMethod method) {
  switch (method) {
    case MinimiserMethod::lbfgs:
      return "lbfgs";
    case MinimiserMethod::fire:
      return "fire";
    case MinimiserMethod::newton:
      return "newton";
  }
  return "unknown";
}

std::string to_string(MinimiserStatus status) {
  switch (status) {
    case MinimiserStatus::converged:
      return "converged";
    case MinimiserStatus::max_iterations:
      return "max_iterations";
    case MinimiserStatus::line_search_failed:
      return "line_search_failed";
    case MinimiserStatus::stalled:
      return "stalled";
    case MinimiserStatus::not_finite:
      return "not_finite";
  }
  return "unknown";
}

void MinimiserOptions::validate() const {
  const auto fail = [](const std::string& what) {
    throw std::invalid_argument("MinimiserOptions: " + what);
  };
  if (!(force_tolerance > 0.0)) fail("force_tolerance must be > 0");
  if (!(energy_tolerance >= 0.0)) fail("energy_tolerance must be >= 0");
  if (std::isnan(force_scale)) fail("force_scale must be a number (<= 0: k_eff l_e)");
  if (max_iterations < 1) fail("max_iterations must be >= 1");
  if (max_outer_iterations < 1) fail("max_outer_iterations must be >= 1");
  if (lbfgs_memory < 1) fail("lbfgs_memory must be >= 1");
  if (!(max_step > 0.0)) fail("max_step must be > 0");
  if (!(preconditioner_reuse >= 0.0) || !std::isfinite(preconditioner_reuse)) {
    fail("preconditioner_reuse must be finite and >= 0");
  }
  if (!(correction_forcing >= 0.0 && correction_forcing < 1.0)) {
    fail("correction_forcing must be in [0, 1)");
  }
  if (newton.max_krylov_iterations < 1) fail("newton.max_krylov_iterations must be >= 1");
  if (!(newton.forcing_max > 0.0 && newton.forcing_max < 1.0)) {
    fail("newton.forcing_max must be in (0, 1)");
  }
  if (distributed != nullptr && method == MinimiserMethod::lbfgs && precondition &&
      lbfgs_preconditioner == LbfgsPreconditioner::multigrid) {
    fail("the multigrid preconditioner cannot split its work over MPI processes yet");
  }
  if (distributed != nullptr && method == MinimiserMethod::newton) {
    fail("method newton cannot split its work over MPI processes yet (docs/mpi.md); use lbfgs");
  }
  if (!(newton.amg.threshold >= 0.0) || newton.amg.smoothings < 0) {
    fail("newton.amg parameters out of range");
  }
  if (fire.n_min < 0 || !(fire.f_inc >= 1.0) || !(fire.f_dec > 0.0 && fire.f_dec < 1.0) ||
      !(fire.alpha_start > 0.0 && fire.alpha_start < 1.0) ||
      !(fire.f_alpha > 0.0 && fire.f_alpha <= 1.0) || !(fire.dt_max_factor > 0.0) ||
      !(fire.dt_start_factor > 0.0) || fire.power_iterations < 1) {
    fail("fire parameters out of range");
  }
}

double max_free_force(const MessSystem& system, const Eigen::Matrix3Xd& gradient) {
  const DofMap map(system.constraints(), system.positions(), 1.0);
  return detail::ForceMeasure(system, map).max_force(gradient);
}

namespace {

using detail::ForceMeasure;
using detail::InnerResult;
using detail::LbfgsMemory;
using detail::LinePoint;
using detail::Objective;
using detail::StallGuard;
using detail::wolfe_line_search;

// -------------------------------------------------------------------------------- L-BFGS

// `precondition`: P of H0 = gamma P (null: the identity), symmetric. `memory`: the pairs to
// start from (empty: a fresh start), formed with this P (they hold P y); it holds the run's
// pairs on return.
InnerResult run_lbfgs(Objective& f, Eigen::VectorXd& u, int budget, const MinimiserOptions& opt,
                      const LbfgsMemory::Preconditioner* precondition, bool use_energy,
                      const std::function<bool(const Eigen::VectorXd&, double)>& converged,
                      LbfgsMemory& memory) {
  const LbfgsMemory::Preconditioner P = [&](const Eigen::VectorXd& v) -> Eigen::VectorXd {
    return precondition != nullptr ? (*precondition)(v) : v;
  };
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
  // A new inner run's objective (the passes' load, the centre rule, M) may differ from the one
  // the newest pair was taken on.
  memory.new_objective();
  int failures = 0;
  constexpr int kStallIterations = 50;
  StallGuard guard(cur.g, kStallIterations);
  while (r.iterations < budget) {
    Eigen::VectorXd d = memory.times(cur.g, P);
    detail::parallel_scale(-1.0, d);  // d = -d in place (exact): no second vector
    cur.dphi = detail::parallel_dot(cur.g, d);
    if (!(cur.dphi < 0.0)) {  // not a descent direction: restart from steepest descent
      memory.clear();
      d = -P(cur.g);
      cur.dphi = detail::parallel_dot(cur.g, d);
    }
    const double dmax = detail::parallel_max_abs(d);
    const double alpha_max = opt.max_step / dmax;
    // Without curvature information (no memory, no preconditioner) the first step is limited
    // to a tenth of max_step.
    const double alpha_init =
        memory.empty() && precondition == nullptr ? std::min(1.0, 0.1 * alpha_max) : 1.0;
    LinePoint next;
    const bool ok = wolfe_line_search(f, u, d, cur, alpha_init, alpha_max, use_energy, next);
    ++r.iterations;
    if (!ok) {
      if (memory.empty() || ++failures >= 2) {
        r.status = MinimiserStatus::line_search_failed;
        return r;
      }
      memory.clear();
      continue;
    }
    failures = 0;
    detail::parallel_axpy(next.alpha, d, u);
    r.energy_change = next.phi - cur.phi;
    memory.add(next.alpha, d, next.g, cur.g, opt.lbfgs_memory);
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

// ------------------------------------------------------------------ evaluation rules

// The minimiser's own evaluation rules, set on the system for the duration of one minimise()
// call: where the particle centres are (CentreRule) and when M is re-solved
// (MagnetizationUpdate). The caller's settings are kept here and written back whole when the
// view goes out of scope, on return and on an exception alike, so minimise() leaves settings()
// as it found them. Every change of rule during the call goes through this view.
class RelaxationRules {
 public:
  explicit RelaxationRules(MessSystem& system) : system_(system), caller_(system.settings()) {}
  RelaxationRules(const RelaxationRules&) = delete;
  RelaxationRules& operator=(const RelaxationRules&) = delete;
  RelaxationRules(RelaxationRules&&) = delete;
  RelaxationRules& operator=(RelaxationRules&&) = delete;
  ~RelaxationRules() { system_.settings() = caller_; }

  const MessSettings& caller() const { return caller_; }
  CentreRule centre_rule() const { return system_.settings().centre_rule; }
  MagnetizationUpdate magnetization_update() const {
    return system_.settings().magnetization_update;
  }
  void set_centre_rule(CentreRule rule) { system_.settings().centre_rule = rule; }
  void set_magnetization_update(MagnetizationUpdate update) {
    system_.settings().magnetization_update = update;
  }

 private:
  MessSystem& system_;
  const MessSettings caller_;
};

// --------------------------------------------------------------------------------- FIRE

// Largest eigenvalue of M^-1 H (scaled units) by power iteration with finite-difference
// Hessian-vector products; the magnetization stays fixed meanwhile. Returns
// omega_max = sqrt(lambda_max).
double estimate_omega_max(Objective& f, RelaxationRules& rules, const Eigen::VectorXd& u,
                          const Eigen::VectorXd& g0, const Eigen::VectorXd& inv_mass,
                          int iterations) {
  const MagnetizationUpdate update = rules.magnetization_update();
  rules.set_magnetization_update(MagnetizationUpdate::manual);
  std::mt19937_64 gen(12345);
  std::normal_distribution<double> normal;
  Eigen::VectorXd v(u.size());
  for (Eigen::Index k = 0; k < v.size(); ++k) v[k] = normal(gen);
  v.normalize();
  double lambda = 0.0;
  Eigen::VectorXd g;
  for (int it = 0; it < iterations; ++it) {
    // Symmetric form: w = M^-1/2 H M^-1/2 v.
    const Eigen::VectorXd mv = inv_mass.cwiseSqrt().cwiseProduct(v);
    const double eps = 1e-6 / std::max(mv.cwiseAbs().maxCoeff(), 1e-300);
    (void)f(u + eps * mv, g);
    const Eigen::VectorXd w = inv_mass.cwiseSqrt().cwiseProduct((g - g0) / eps);
    lambda = v.dot(w);
    const double norm = w.norm();
    if (!(norm > 0.0)) break;
    v = w / norm;
  }
  rules.set_magnetization_update(update);
  (void)f(u, g);  // back to the starting point
  return std::sqrt(std::max(lambda, 1e-300));
}

InnerResult run_fire(Objective& f, RelaxationRules& rules, Eigen::VectorXd& u, int budget,
                     const MinimiserOptions& opt, const Eigen::VectorXd& mass,
                     const std::function<bool(const Eigen::VectorXd&, double)>& converged) {
  const FireParameters& p = opt.fire;
  InnerResult r;
  Eigen::VectorXd g;
  double phi = f(u, g);
  if (!std::isfinite(phi)) {
    r.status = MinimiserStatus::not_finite;
    return r;
  }
  if (converged(g, 0.0)) {
    r.status = MinimiserStatus::converged;
    return r;
  }
  const Eigen::VectorXd inv_mass = mass.cwiseInverse();
  const double omega = estimate_omega_max(f, rules, u, g, inv_mass, p.power_iterations);
  const double dt_max = p.dt_max_factor / omega;
  double dt = p.dt_start_factor / omega;
  double alpha = p.alpha_start;
  int n_positive = 0;
  Eigen::VectorXd v = Eigen::VectorXd::Zero(u.size());
  while (r.iterations < budget) {
    ++r.iterations;
    const double power = -g.dot(v);  // F . v
    if (power > 0.0) {
      if (++n_positive > p.n_min) {
        dt = std::min(dt * p.f_inc, dt_max);
        alpha *= p.f_alpha;
      }
    } else {
      n_positive = 0;
      dt *= p.f_dec;
      alpha = p.alpha_start;
      u -= 0.5 * dt * v;  // FIRE 2.0: step back half a step
      v.setZero();
    }
    // Semi-implicit Euler with the FIRE velocity mixing v <- (1 - a) v + a |v| F^.
    v -= dt * inv_mass.cwiseProduct(g);
    const double gnorm = g.norm();
    if (gnorm > 0.0) v = (1.0 - alpha) * v - alpha * v.norm() / gnorm * g;
    Eigen::VectorXd step = dt * v;
    const double smax = step.cwiseAbs().maxCoeff();
    if (smax > opt.max_step) {
      step *= opt.max_step / smax;
      v *= opt.max_step / smax;
    }
    u += step;
    const double phi_new = f(u, g);
    if (!std::isfinite(phi_new)) {
      r.status = MinimiserStatus::not_finite;
      return r;
    }
    r.energy_change = phi_new - phi;
    phi = phi_new;
    if (converged(g, r.energy_change)) {
      r.status = MinimiserStatus::converged;
      return r;
    }
  }
  return r;
}

// ------------------------------------------------------------------------- outer loop

// One minimise() call after its set-up: the inner minimisations (L-BFGS or FIRE), the phases
// and fallbacks of the header between them, and the final report.
class Minimisation {
 public:
  Minimisation(MessSystem& system, RelaxationRules& rules, const DofMap& map,
               const MinimiserOptions& options, double force_scale, bool alternating)
      : system_(system),
        rules_(rules),
        opt_(options),
        force_scale_(force_scale),
        map_(map),
        measure_(system, map),
        f_(system, map, force_scale, options.distributed.get()),
        u_(map.to_dofs(system.positions())),
        alternating_(alternating),
        budget_(options.max_iterations),
        method_(options.method) {
    bool multilevel = false;
    if (options.precondition && options.method != MinimiserMethod::fire &&
        options.lbfgs_preconditioner != LbfgsPreconditioner::multigrid) {
      multilevel = options.lbfgs_preconditioner == LbfgsPreconditioner::multilevel ||
                   (options.lbfgs_preconditioner == LbfgsPreconditioner::automatic &&
                    system.node_count() >= kMultilevelMinimumNodes);
      // Over MPI processes they share the multilevel correction's build (docs/mpi.md).
      const detail::BlockSplit* processes =
          options.distributed != nullptr ? options.distributed->vector_split().get() : nullptr;
      preconditioner_ =
          options.preconditioner_cache != nullptr
              ? options.preconditioner_cache->get(system, map, force_scale, multilevel, processes,
                                                  options.node_scaling, options.contact_gap,
                                                  options.preconditioner_reuse)
              : std::make_shared<const RigidParticlePreconditioner>(
                    system, map, force_scale, multilevel,
                    multilevel ? &system.positions() : nullptr,  // as the cache builds it
                    processes, options.node_scaling, options.contact_gap);
      if (multilevel) {
        const bool kept =
            options.preconditioner_cache != nullptr && options.preconditioner_cache->last_kept();
        res_.state_preconditioner = kept ? "kept" : "built";
      }
    }
    const bool single = options.lbfgs_history == LbfgsHistoryPrecision::single_precision ||
                        (options.lbfgs_history == LbfgsHistoryPrecision::automatic && multilevel);
    lbfgs_memory_.set_precision(single ? detail::LbfgsPrecision::single_precision
                                       : detail::LbfgsPrecision::double_precision);
    // Over MPI processes each keeps only its blocks of the L-BFGS pairs (docs/mpi.md).
    if (options.distributed != nullptr) {
      lbfgs_memory_.set_split(options.distributed->vector_split());
    }
    res_.force_scale = force_scale;
  }

  // L-BFGS needs forces that are the potential's gradient. The seed's centre-voxel spreading is
  // not quite (it differs by the particles' internal deformation), so L-BFGS first relaxes the
  // conservative neighbour (centre = mean of all nodes, exact gradient); the seed's own forces
  // are then checked and, if they exceed the tolerance, relaxed (end_conservative_phase).
  MinimiserResult run() {
    conservative_phase_ =
        method_ != MinimiserMethod::fire && caller_centre_rule() == CentreRule::centre_voxel;
    if (conservative_phase_) rules_.set_centre_rule(CentreRule::all_nodes);
    if (conservative_phase_ && method_ == MinimiserMethod::lbfgs && opt_.correction_forcing > 0) {
      set_inner_tolerance(force_difference_at_start());
    }
    for (int outer = 0; outer < opt_.max_outer_iterations && budget_ > 0; ++outer) {
      if (!outer_iteration()) break;
    }
    f_.clear_load();
    rules_.set_centre_rule(caller_centre_rule());
    // Final state and report (M re-solved once more with every_evaluation).
    evaluate_here();
    if (correcting_ && res_.status == MinimiserStatus::converged && !forces_below_tolerance()) {
      // The outer iterations ran out in a correction pass: it converged on its own
      // objective, not on the seed's forces.
      res_.status = MinimiserStatus::max_iterations;
    }
    res_.final = f_.last_evaluation();
    res_.correction_passes = correction_passes_;
    res_.max_force = measure_.max_force(f_.full_gradient());
    res_.evaluations = f_.evaluations();
    if (newton_ != nullptr) {
      res_.krylov_iterations = newton_->krylov_iterations();
      res_.preconditioner_seconds = newton_->preconditioner_seconds();
      res_.multigrid_seconds = newton_->timings().multigrid;
      res_.hessian_product_seconds = newton_->timings().products;
      res_.centre_hessian_seconds = newton_->timings().centre_hessian;
    }
    res_.converged = res_.status == MinimiserStatus::converged;
    return res_;
  }

 private:
  CentreRule caller_centre_rule() const { return rules_.caller().centre_rule; }

  void evaluate_here() {
    Eigen::VectorXd g;
    (void)f_(u_, g);
  }

  bool forces_below_tolerance() const {
    return measure_.max_force(f_.full_gradient()) <= opt_.force_tolerance * force_scale_;
  }

  // The inner minimisations' convergence test; also what the observer is shown. A loose
  // inner run (set_inner_tolerance) tests the force alone.
  bool converged(double energy_change) {
    const double max_force = measure_.max_force(f_.full_gradient());
    if (opt_.observer) opt_.observer({++convergence_checks_, max_force});
    if (!inner_tight_) return max_force <= inner_force_tolerance_ * force_scale_;
    // Energy change relative to the potential's size, but never below the energy scale E0:
    // tiny energies (a block at 1e-4 strain) are dominated by their own rounding noise.
    return max_force <= opt_.force_tolerance * force_scale_ &&
           std::abs(energy_change) <= opt_.energy_tolerance * std::max(f_.magnitude(), 1.0);
  }

  // The seed's L-BFGS route (the conservative phase and the correction passes) as inexact
  // defect correction: an inner run need only resolve its objective well below what the next
  // pass's frozen load will correct anyway (`to_correct`, N: the seed's force at a pass's
  // start, the seed-neighbour force difference for the conservative phase); resolving it
  // further is spent twice. Its force tolerance is correction_forcing x to_correct, never below
  // force_tolerance (then with the energy test too: the run that may end the relaxation is a
  // tight one).
  void set_inner_tolerance(double to_correct) {
    const double loose = opt_.correction_forcing * to_correct / force_scale_;
    inner_tight_ = !(loose > opt_.force_tolerance);
    inner_force_tolerance_ = inner_tight_ ? opt_.force_tolerance : loose;
  }
  // The largest difference between the seed's forces and its conservative neighbour's at the
  // starting state (N): what the first correction pass will have to correct, so what the
  // conservative phase need resolve. (Not the seed's force itself: after a field step that is
  // the whole new magnetic force, and a phase ended at a fraction of it may stop halfway
  // through a snap into contact, in another basin.)
  double force_difference_at_start() {
    rules_.set_centre_rule(caller_centre_rule());
    evaluate_here();
    Eigen::Matrix3Xd difference = f_.full_gradient();
    rules_.set_centre_rule(CentreRule::all_nodes);
    evaluate_here();
    difference -= f_.full_gradient();
    return measure_.max_force(difference);
  }
  void set_tight_inner_tolerance() {
    inner_tight_ = true;
    inner_force_tolerance_ = opt_.force_tolerance;
  }

  InnerResult run_inner() {
    const auto test = [this](const Eigen::VectorXd& /*g*/, double energy_change) {
      return converged(energy_change);
    };
    // Newton; in the seed's forces-only phase with the conservative neighbour's Hessian as the
    // Jacobian of the seed's forces (they differ by the particles' internal deformation).
    if (method_ == MinimiserMethod::newton) {
      return newton_solver().run(f_, u_, budget_, opt_, use_energy_, test);
    }
    if (method_ == MinimiserMethod::fire) {
      // Nodal masses in units of m_c, formed only when FIRE runs: kept through every L-BFGS
      // run they would cost 24 bytes per node at its peak.
      const Eigen::VectorXd mass = map_.reduce_masses(system_.lattice().masses) /
                                   detail::characteristic_mass(system_.lattice());
      return run_fire(f_, rules_, u_, budget_, opt_, mass, test);
    }
    LbfgsMemory::Preconditioner P;
    if (preconditioner_ != nullptr) {
      P = [this](const Eigen::VectorXd& v) { return preconditioner_->apply(map_, v); };
    } else if (opt_.precondition) {
      // Newton's multigrid; its contact correction at the state this inner run starts from.
      detail::NewtonSolver& newton = newton_solver();
      newton.update_centre_hessian();
      P = [&newton](const Eigen::VectorXd& v) { return newton.precondition(v); };
      lbfgs_memory_.preconditioner_changed();  // its pairs hold P y of the previous P
    }
    return run_lbfgs(f_, u_, budget_, opt_, P ? &P : nullptr, use_energy_, test, lbfgs_memory_);
  }

  // Newton's solver (newton.hpp), built on first use: the method, or L-BFGS's multigrid.
  detail::NewtonSolver& newton_solver() {
    if (newton_ == nullptr) {
      newton_ = std::make_unique<detail::NewtonSolver>(system_, map_, force_scale_, opt_.newton,
                                                       opt_.newton_cache);
    }
    return *newton_;
  }

  // One outer iteration; false ends the loop.
  bool outer_iteration() {
    if (alternating_ && system_.particle_count() > 0) {
      (void)system_.solve_magnetization();
      ++res_.outer_iterations;
    }
    if (correcting_) {
      if (!begin_correction_pass()) return false;
    } else {
      lbfgs_memory_.clear();  // a new objective or rule: the pairs no longer describe it
    }
    const InnerResult inner = run_inner();
    budget_ -= inner.iterations;
    res_.iterations += inner.iterations;
    res_.energy_change = inner.energy_change * f_.energy_scale();
    res_.status = inner.status;
    const bool failed = inner.status == MinimiserStatus::line_search_failed ||
                        inner.status == MinimiserStatus::stalled;
    if (failed && !alternating_ && system_.particle_count() > 0 &&
        rules_.centre_rule() == CentreRule::all_nodes) {
      // M(x) re-solved to a finite tolerance makes the reduced energy slightly rough; where
      // that stalls the line search, continue at fixed M between re-solves.
      alternating_ = true;
      res_.switched_to_alternating = true;
      rules_.set_magnetization_update(MagnetizationUpdate::manual);
      return true;
    }
    if (conservative_phase_ && (failed || inner.status == MinimiserStatus::converged)) {
      return end_conservative_phase(inner.status);
    }
    if (correcting_) return end_correction_pass(inner.status);
    if (failed) {
      if (method_ == MinimiserMethod::fire) return false;
      if (method_ == MinimiserMethod::newton) {
        // Newton's line search failed twice in a row: L-BFGS continues from here.
        method_ = MinimiserMethod::lbfgs;
        res_.finished_with_lbfgs = true;
        return true;
      }
      // Rounding or M-roughness L-BFGS cannot get through: FIRE needs forces only.
      method_ = MinimiserMethod::fire;
      res_.finished_with_fire = true;
      return true;
    }
    if (inner.status != MinimiserStatus::converged) {
      return inner.status == MinimiserStatus::max_iterations;
    }
    if (!alternating_ || system_.particle_count() == 0) return false;
    // Re-solve M at the relaxed positions; done if the forces stay below the tolerance.
    (void)system_.solve_magnetization();
    evaluate_here();
    if (forces_below_tolerance()) return false;
    res_.status = MinimiserStatus::max_iterations;  // not yet: another outer iteration
    return true;
  }

  // Back to the caller's centre rule (the seed's centre voxel); false if its forces are below
  // the tolerance too, else L-BFGS continues on them: in correction passes after a converged
  // conservative phase, with the slope-only line search otherwise (and Newton on its own).
  bool end_conservative_phase(MinimiserStatus status) {
    conservative_phase_ = false;
    rules_.set_centre_rule(caller_centre_rule());
    evaluate_here();
    if (status == MinimiserStatus::converged && inner_tight_ && forces_below_tolerance()) {
      return false;
    }
    res_.forces_only_phase = true;
    if (status == MinimiserStatus::converged && method_ == MinimiserMethod::lbfgs) {
      correcting_ = true;  // the next outer iterations are correction passes
      return true;
    }
    set_tight_inner_tolerance();
    use_energy_ = false;
    res_.slope_only_fallback = method_ == MinimiserMethod::lbfgs;
    return true;
  }

  // Correction passes for the seed's forces (L-BFGS). The seed's gradient differs from its
  // conservative neighbour's by delta(x): the centre voxel carries each particle's whole
  // magnetic and contact force where the neighbour spreads it over the particle. delta changes
  // with x only through the particles' internal deformation and the pair's small moves, so a
  // pass freezes it at the current state x_k and minimises the neighbour's potential plus the
  // constant load delta(x_k) . x: a true potential, so the energy line search works, and the
  // L-BFGS pairs of the conservative phase and of the passes before stay valid (a constant
  // load leaves the Hessian as it was). The pass's minimum has g_seed = delta(x) - delta(x_k),
  // a factor 3e-3 (apart) to 0.07 (in contact) below the seed's force at x_k; each pass is
  // run only to correction_forcing x that force (set_inner_tolerance), and the passes repeat
  // until the seed's own forces meet the tolerance after a tight one. Where L-BFGS on the seed's
  // forces with the slope-only line search stalled in contact at full size and FIRE had to finish,
  // the passes converge (docs/performance.md). False: the seed's forces meet the tolerance.
  bool begin_correction_pass() {
    f_.clear_load();
    rules_.set_centre_rule(caller_centre_rule());
    evaluate_here();
    const double seed_force = measure_.max_force(f_.full_gradient());
    // Done once the seed's forces meet the tolerance after a tight pass (a loose one has not
    // been tested on the energy change).
    if (inner_tight_ && seed_force <= opt_.force_tolerance * force_scale_) {
      res_.status = MinimiserStatus::converged;
      return false;
    }
    set_inner_tolerance(seed_force);
    Eigen::Matrix3Xd load = f_.full_gradient();  // the seed's gradient at x_k
    rules_.set_centre_rule(CentreRule::all_nodes);
    evaluate_here();
    load -= f_.full_gradient();  // in place: no second full-size temporary
    f_.set_load(load, u_);
    ++correction_passes_;
    return true;
  }

  // After a pass: the next one if it converged; otherwise (or after kMaxCorrectionPasses)
  // L-BFGS continues on the seed's own forces with the slope-only line search, as before the
  // passes existed, and FIRE after that.
  bool end_correction_pass(MinimiserStatus status) {
    if (status == MinimiserStatus::converged && correction_passes_ < kMaxCorrectionPasses) {
      return true;
    }
    correcting_ = false;
    f_.clear_load();
    rules_.set_centre_rule(caller_centre_rule());
    set_tight_inner_tolerance();
    if (status == MinimiserStatus::max_iterations && budget_ <= 0) return false;
    use_energy_ = false;
    res_.slope_only_fallback = true;
    return true;
  }

  MessSystem& system_;
  RelaxationRules& rules_;
  const MinimiserOptions& opt_;
  double force_scale_;
  const DofMap& map_;
  const ForceMeasure measure_;
  Objective f_;
  Eigen::VectorXd u_;
  std::shared_ptr<const RigidParticlePreconditioner> preconditioner_;
  std::unique_ptr<detail::NewtonSolver> newton_;
  MinimiserResult res_;
  bool alternating_;
  int budget_;
  MinimiserMethod method_;
  bool use_energy_ = true;
  bool conservative_phase_ = false;
  bool correcting_ = false;  // the seed's correction passes (begin_correction_pass)
  // The current inner run's force tolerance (units of force_scale) and whether it is the
  // caller's, with the energy test (set_inner_tolerance).
  double inner_force_tolerance_ = opt_.force_tolerance;
  bool inner_tight_ = true;
  int correction_passes_ = 0;
  static constexpr int kMaxCorrectionPasses = 20;
  LbfgsMemory lbfgs_memory_;  // kept from one inner run to the next only by the passes
  std::int64_t convergence_checks_ = 0;
};

}  // namespace

// --------------------------------------------------------------------------- minimise

MinimiserResult minimise(MessSystem& system, const MinimiserOptions& options) {
  options.validate();
  const double l_e = system.length_scale();
  const double force_scale = options.force_scale > 0.0
                                 ? options.force_scale
                                 : LeapfrogScales::of(system.lattice()).k_eff * l_e;
  RelaxationRules rules(system);  // the caller's settings come back on every exit
  const bool alternating = options.coupling == MagnetizationCoupling::alternating;
  rules.set_magnetization_update(alternating ? MagnetizationUpdate::manual
                                             : MagnetizationUpdate::every_evaluation);
  const MagnetizationStats stats0 = system.magnetization_stats();

  system.apply_constraints();
  const DofMap map(system.constraints(), system.positions(), l_e);
  MinimiserResult res = Minimisation(system, rules, map, options, force_scale, alternating).run();
  const MagnetizationStats& stats = system.magnetization_stats();
  res.magnetization_solves = stats.solves - stats0.solves;
  res.unconverged_magnetization_solves = stats.unconverged - stats0.unconverged;
  return res;
}

}  // namespace mresim::mess
