#include "mresim/mess/solvers/minimiser.hpp"

#include <algorithm>
#include <cmath>
#include <deque>
#include <functional>
#include <limits>
#include <memory>
#include <random>
#include <stdexcept>

#include "mresim/mess/solvers/leapfrog.hpp"
#include "mresim/mess/solvers/preconditioner.hpp"
#include "mresim/mess/solvers/relaxation_common.hpp"

namespace mresim::mess {

std::string to_string(MinimiserMethod method) {
  return method == MinimiserMethod::lbfgs ? "lbfgs" : "fire";
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
using detail::Objective;

struct InnerResult {
  MinimiserStatus status = MinimiserStatus::max_iterations;
  int iterations = 0;
  double energy_change = 0.0;  // scaled
};

// -------------------------------------------------------------------------- line search

struct LinePoint {
  double alpha = 0.0;
  double phi = 0.0;   // scaled potential
  double dphi = 0.0;  // directional derivative g . d
  Eigen::VectorXd g;
};

// Strong-Wolfe line search (Nocedal & Wright Alg. 3.5/3.6) along d from u, with a rounding
// slack on the sufficient-decrease test and derivative (secant) interpolation in the zoom.
// On success `out` holds the accepted point and the system is left at it.
// use_energy = false: forces only (a field that is not exactly a gradient): the energy tests
// are dropped and the search brackets the zero of the slope g(alpha) . d.
bool wolfe_line_search(Objective& f, const Eigen::VectorXd& u, const Eigen::VectorXd& d,
                       LinePoint start, double alpha_init, double alpha_max, bool use_energy,
                       LinePoint& out) {
  start.alpha = 0.0;
  constexpr double c1 = 1e-4;
  constexpr double c2 = 0.9;
  constexpr int kMaxTrials = 40;
  const double slack = 64.0 * std::numeric_limits<double>::epsilon() * f.magnitude();
  double last_alpha = 0.0;  // where the system was evaluated last
  const auto eval = [&](double alpha) {
    last_alpha = alpha;
    LinePoint p;
    p.alpha = alpha;
    p.phi = f(u + alpha * d, p.g);
    p.dphi = p.g.dot(d);
    return p;
  };
  const auto armijo_fails = [&](const LinePoint& p) {
    return !std::isfinite(p.phi) || !std::isfinite(p.dphi) ||
           (use_energy && p.phi > start.phi + c1 * p.alpha * start.dphi + slack);
  };
  const auto higher = [&](const LinePoint& p, const LinePoint& than) {
    return use_energy && p.phi > than.phi + slack;
  };
  const auto curvature_holds = [&](const LinePoint& p) {
    return std::abs(p.dphi) <= -c2 * start.dphi;
  };
  int trials = 0;
  // zoom(lo, hi): lo satisfies sufficient decrease, the minimiser lies between lo and hi.
  const auto zoom = [&](LinePoint lo, LinePoint hi) {
    while (trials < kMaxTrials) {
      const double a = std::min(lo.alpha, hi.alpha);
      const double b = std::max(lo.alpha, hi.alpha);
      double alpha;
      if (std::isfinite(hi.phi) && lo.dphi * hi.dphi < 0.0) {
        alpha = lo.alpha - lo.dphi * (hi.alpha - lo.alpha) / (hi.dphi - lo.dphi);  // secant on phi'
      } else {
        alpha = 0.5 * (a + b);
      }
      alpha = std::clamp(alpha, a + 0.1 * (b - a), b - 0.1 * (b - a));
      const LinePoint p = eval(alpha);
      ++trials;
      if (armijo_fails(p) || higher(p, lo)) {
        hi = p;
      } else {
        if (curvature_holds(p)) {
          out = p;
          return true;
        }
        if (p.dphi * (hi.alpha - lo.alpha) >= 0.0) hi = lo;
        lo = p;
      }
      if (std::abs(hi.alpha - lo.alpha) < 1e-12 * std::max(lo.alpha, hi.alpha)) break;
    }
    // Accept the best point with sufficient decrease if it made progress: lower energy beyond
    // the noise, or a smaller slope.
    if (lo.alpha > 0.0 && ((use_energy && lo.phi < start.phi - slack) ||
                           std::abs(lo.dphi) < 0.5 * std::abs(start.dphi))) {
      out = lo;
      return true;
    }
    return false;
  };

  LinePoint prev = start;
  double alpha = std::min(alpha_init, alpha_max);
  bool ok = false;
  while (trials < kMaxTrials) {
    const LinePoint p = eval(alpha);
    ++trials;
    if (armijo_fails(p) || (prev.alpha > 0.0 && higher(p, prev))) {
      ok = zoom(prev, p);
      break;
    }
    if (curvature_holds(p)) {
      out = p;
      ok = true;
      break;
    }
    if (p.dphi >= 0.0) {
      ok = zoom(p, prev);
      break;
    }
    if (alpha >= alpha_max) {  // cannot go further: accept the longest allowed step
      out = p;
      ok = true;
      break;
    }
    prev = p;
    alpha = std::min(2.0 * alpha, alpha_max);
  }
  if (ok && last_alpha != out.alpha) {
    Eigen::VectorXd g;
    (void)f(u + out.alpha * d, g);  // leave the system at the accepted point
  }
  return ok;
}

// -------------------------------------------------------------------------------- L-BFGS

InnerResult run_lbfgs(Objective& f, Eigen::VectorXd& u, int budget, const MinimiserOptions& opt,
                      const RigidParticlePreconditioner* precondition, bool use_energy,
                      const std::function<bool(const Eigen::VectorXd&, double)>& converged) {
  const auto P = [&](const Eigen::VectorXd& v) -> Eigen::VectorXd {
    return precondition != nullptr ? precondition->apply(v) : v;
  };
  InnerResult r;
  std::deque<Eigen::VectorXd> S;
  std::deque<Eigen::VectorXd> Y;
  std::deque<double> rho;
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
  int failures = 0;
  constexpr int kStallIterations = 50;
  int stalled = 0;
  double best_gradient = cur.g.cwiseAbs().maxCoeff();
  while (r.iterations < budget) {
    // Two-loop recursion (N&W Alg. 7.4), H0 = (s.y / y.P y) P.
    Eigen::VectorXd q = cur.g;
    std::vector<double> a(S.size());
    for (int i = static_cast<int>(S.size()) - 1; i >= 0; --i) {
      const auto k = static_cast<std::size_t>(i);
      a[k] = rho[k] * S[k].dot(q);
      q -= a[k] * Y[k];
    }
    if (!S.empty()) {
      q = P(q) * (S.back().dot(Y.back()) / Y.back().dot(P(Y.back())));
    } else {
      q = P(q);
    }
    for (std::size_t k = 0; k < S.size(); ++k) {
      const double b = rho[k] * Y[k].dot(q);
      q += (a[k] - b) * S[k];
    }
    Eigen::VectorXd d = -q;
    cur.dphi = cur.g.dot(d);
    if (!(cur.dphi < 0.0)) {  // not a descent direction: restart from steepest descent
      S.clear();
      Y.clear();
      rho.clear();
      d = -P(cur.g);
      cur.dphi = cur.g.dot(d);
    }
    const double dmax = d.cwiseAbs().maxCoeff();
    const double alpha_max = opt.max_step / dmax;
    // Without curvature information (no memory, no preconditioner) the first step is limited
    // to a tenth of max_step.
    const double alpha_init =
        S.empty() && precondition == nullptr ? std::min(1.0, 0.1 * alpha_max) : 1.0;
    LinePoint next;
    const bool ok = wolfe_line_search(f, u, d, cur, alpha_init, alpha_max, use_energy, next);
    ++r.iterations;
    if (!ok) {
      if (S.empty() || ++failures >= 2) {
        r.status = MinimiserStatus::line_search_failed;
        return r;
      }
      S.clear();
      Y.clear();
      rho.clear();
      continue;
    }
    failures = 0;
    Eigen::VectorXd s = next.alpha * d;
    Eigen::VectorXd y = next.g - cur.g;
    u += s;
    r.energy_change = next.phi - cur.phi;
    const double sy = s.dot(y);
    if (sy > 1e-12 * y.squaredNorm() && sy > 0.0) {
      S.push_back(std::move(s));
      Y.push_back(std::move(y));
      rho.push_back(1.0 / sy);
      if (static_cast<int>(S.size()) > opt.lbfgs_memory) {
        S.pop_front();
        Y.pop_front();
        rho.pop_front();
      }
    }
    cur = std::move(next);
    // Stall guard: no energy decrease beyond rounding and no new smallest gradient for a while.
    const double gmax = cur.g.cwiseAbs().maxCoeff();
    const double noise = 64.0 * std::numeric_limits<double>::epsilon() * f.magnitude();
    if (gmax < best_gradient || (use_energy && r.energy_change < -noise)) {
      best_gradient = std::min(best_gradient, gmax);
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

// --------------------------------------------------------------------------------- FIRE

// Largest eigenvalue of M^-1 H (scaled units) by power iteration with finite-difference
// Hessian-vector products; the magnetization stays fixed meanwhile. Returns
// omega_max = sqrt(lambda_max).
double estimate_omega_max(Objective& f, const Eigen::VectorXd& u, const Eigen::VectorXd& g0,
                          const Eigen::VectorXd& inv_mass, int iterations) {
  MessSettings& settings = f.system().settings();
  const MagnetizationUpdate saved = settings.magnetization_update;
  settings.magnetization_update = MagnetizationUpdate::manual;
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
  settings.magnetization_update = saved;
  (void)f(u, g);  // back to the starting point
  return std::sqrt(std::max(lambda, 1e-300));
}

InnerResult run_fire(Objective& f, Eigen::VectorXd& u, int budget, const MinimiserOptions& opt,
                     const Eigen::VectorXd& mass,
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
  const double omega = estimate_omega_max(f, u, g, inv_mass, p.power_iterations);
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

}  // namespace

// --------------------------------------------------------------------------- minimise

MinimiserResult minimise(MessSystem& system, const MinimiserOptions& options) {
  options.validate();
  const double l_e = system.length_scale();
  const double force_scale = options.force_scale > 0.0
                                 ? options.force_scale
                                 : LeapfrogScales::of(system.lattice()).k_eff * l_e;
  const MagnetizationUpdate saved_update = system.settings().magnetization_update;
  bool alternating = options.coupling == MagnetizationCoupling::alternating;
  system.settings().magnetization_update =
      alternating ? MagnetizationUpdate::manual : MagnetizationUpdate::every_evaluation;
  const MagnetizationStats stats0 = system.magnetization_stats();

  system.apply_constraints();
  const DofMap map(system.constraints(), system.positions(), l_e);
  const ForceMeasure measure(system, map);
  Objective f(system, map, force_scale);
  Eigen::VectorXd u = map.to_dofs(system.positions());
  // Nodal masses in units of m_c (FIRE only).
  const Eigen::VectorXd mass =
      map.reduce_masses(system.lattice().masses) / detail::characteristic_mass(system.lattice());

  std::unique_ptr<RigidParticlePreconditioner> preconditioner;
  if (options.precondition && options.method == MinimiserMethod::lbfgs) {
    preconditioner = std::make_unique<RigidParticlePreconditioner>(system, map, force_scale);
  }

  MinimiserResult res;
  res.force_scale = force_scale;
  const auto converged = [&](const Eigen::VectorXd& /*g*/, double energy_change) {
    const double force = measure.max_force(f.full_gradient());
    // Energy change relative to the potential's size, but never below the energy scale E0:
    // tiny energies (a block at 1e-4 strain) are dominated by their own rounding noise.
    return force <= options.force_tolerance * force_scale &&
           std::abs(energy_change) <= options.energy_tolerance * std::max(f.magnitude(), 1.0);
  };

  int budget = options.max_iterations;
  MinimiserMethod method = options.method;
  // L-BFGS needs forces that are the potential's gradient. The seed's centre-voxel spreading is
  // not quite (it differs by the particles' internal deformation), so L-BFGS first relaxes the
  // conservative neighbour (centre = mean of all nodes, exact gradient); the seed's own forces
  // are then checked, and FIRE (forces only) finishes if they exceed the tolerance.
  const CentreRule centre_rule = system.settings().centre_rule;
  bool use_energy = true;
  bool conservative_phase =
      method == MinimiserMethod::lbfgs && centre_rule == CentreRule::centre_voxel;
  if (conservative_phase) system.settings().centre_rule = CentreRule::all_nodes;
  for (int outer = 0; outer < options.max_outer_iterations && budget > 0; ++outer) {
    if (alternating && system.particle_count() > 0) {
      (void)system.solve_magnetization();
      ++res.outer_iterations;
    }
    const InnerResult inner =
        method == MinimiserMethod::lbfgs
            ? run_lbfgs(f, u, budget, options, preconditioner.get(), use_energy, converged)
            : run_fire(f, u, budget, options, mass, converged);
    budget -= inner.iterations;
    res.iterations += inner.iterations;
    res.energy_change = inner.energy_change * f.energy_scale();
    res.status = inner.status;
    const bool failed = inner.status == MinimiserStatus::line_search_failed ||
                        inner.status == MinimiserStatus::stalled;
    if (failed && !alternating && system.particle_count() > 0 &&
        system.settings().centre_rule == CentreRule::all_nodes) {
      // M(x) re-solved to a finite tolerance makes the reduced energy slightly rough; where
      // that stalls the line search, continue at fixed M between re-solves.
      alternating = true;
      res.switched_to_alternating = true;
      system.settings().magnetization_update = MagnetizationUpdate::manual;
      continue;
    }
    if (conservative_phase && (failed || inner.status == MinimiserStatus::converged)) {
      conservative_phase = false;
      system.settings().centre_rule = centre_rule;
      Eigen::VectorXd g;
      (void)f(u, g);
      if (inner.status == MinimiserStatus::converged &&
          measure.max_force(f.full_gradient()) <= options.force_tolerance * force_scale) {
        break;  // the seed's forces are below the tolerance too
      }
      use_energy = false;  // L-BFGS on the seed's forces, slope-only line search
      res.forces_only_phase = true;
      continue;
    }
    if (failed) {
      if (method == MinimiserMethod::lbfgs) {
        // Rounding or M-roughness L-BFGS cannot get through: FIRE needs forces only.
        method = MinimiserMethod::fire;
        res.finished_with_fire = true;
        continue;
      }
      break;
    }
    if (inner.status != MinimiserStatus::converged) {
      if (inner.status != MinimiserStatus::max_iterations) break;
      continue;
    }
    if (!alternating || system.particle_count() == 0) break;
    // Re-solve M at the relaxed positions; done if the forces stay below the tolerance.
    (void)system.solve_magnetization();
    Eigen::VectorXd g;
    (void)f(u, g);
    if (measure.max_force(f.full_gradient()) <= options.force_tolerance * force_scale) break;
    res.status = MinimiserStatus::max_iterations;  // not yet: another outer iteration
  }
  system.settings().centre_rule = centre_rule;
  // Final state and report (M re-solved once more with every_evaluation).
  Eigen::VectorXd g;
  (void)f(u, g);
  res.final = f.last_evaluation();
  res.max_force = measure.max_force(f.full_gradient());
  res.evaluations = f.evaluations();
  res.converged = res.status == MinimiserStatus::converged;
  const MagnetizationStats& stats = system.magnetization_stats();
  res.magnetization_solves = stats.solves - stats0.solves;
  res.unconverged_magnetization_solves = stats.unconverged - stats0.unconverged;
  system.settings().magnetization_update = saved_update;
  return res;
}

}  // namespace mresim::mess
