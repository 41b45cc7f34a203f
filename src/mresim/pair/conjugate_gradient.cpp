#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>

#include "mresim/pair/relaxation.hpp"
#include "mresim/pair/relaxation_coordinates.hpp"

namespace mresim::pair {
namespace {

// Line search along p from q (energy e, slope slope0 = g.p < 0): grows the trial step until the
// directional derivative turns positive or the energy rises, then secant/bisects on phi'.
// Returns alpha with the energy and gradient there (energy > e: no decrease found).
template <int N, typename Evaluate, typename Vec>
double line_minimum(const Evaluate& evaluate, const Vec& q, double e, const Vec& p, double slope0,
                    const RelaxOptions& opt, double& e_trial, Vec& g_trial,
                    Eigen::Vector3d& g3_trial) {
  double lo = 0.0;
  double slope_lo = slope0;
  // First trial: the minimiser of the quadratic through phi'(0) and the curvature probed with
  // a tiny step (capped at 1% of R). The bracket then closes at the first minimum along the
  // line, so a shallow basin near a critical field (a saddle a fraction of a nanometre past
  // the penalty's edge) is not jumped over.
  const double cap = std::min(1.0, 0.04 * opt.max_step / p.norm());
  const double probe = 1e-9 / p.norm();
  Vec g_probe;
  Eigen::Vector3d g3_probe;
  evaluate(q + probe * p, g_probe, g3_probe);
  const double curvature = (g_probe.dot(p) - slope0) / probe;
  double hi = curvature > 0.0 ? std::min(cap, -slope0 / curvature) : cap;
  double slope_hi = 0.0;
  for (int grow = 0; grow < 60; ++grow) {
    e_trial = evaluate(q + hi * p, g_trial, g3_trial);
    slope_hi = g_trial.dot(p);
    if (slope_hi >= 0.0 || e_trial > e) break;
    lo = hi;
    slope_lo = slope_hi;
    hi *= 2.0;
  }
  double alpha = hi;
  for (int refine = 0; refine < 60 && (slope_hi > 0.0 || e_trial > e); ++refine) {
    // Secant estimate of phi' = 0, kept inside the bracket; bisection if it strays.
    double trial =
        slope_hi > 0.0 ? lo - slope_lo * (hi - lo) / (slope_hi - slope_lo) : 0.5 * (lo + hi);
    if (!(trial > lo && trial < hi) || e_trial > e) trial = 0.5 * (lo + hi);
    alpha = trial;
    e_trial = evaluate(q + alpha * p, g_trial, g3_trial);
    const double slope = g_trial.dot(p);
    if (e_trial <= e && std::abs(slope) <= 0.1 * std::abs(slope0)) break;
    if (slope > 0.0 || e_trial > e) {
      hi = alpha;
      slope_hi = slope;
    } else {
      lo = alpha;
      slope_lo = slope;
    }
    if (hi - lo <= 1e-16 * (1.0 + alpha)) break;
  }
  return alpha;
}

}  // namespace

// Polak-Ribiere+ conjugate gradients, preconditioned with the diagonal of the Hessian in the
// polar coordinates: next to a penalty wall the radial curvature is ~1e12 times the rotational
// one, and unpreconditioned steps (limited by the wall) leave the rotation unresolved by
// nanometres while each step looks negligible. Convergence is the same test as Newton's: the
// gradient below tolerance, or at the resolution of the arithmetic with the minimum verified
// between q and twice the diagonal Newton step (detail::probe_minimum).
template <int N>
RelaxResult relax_conjugate_gradient(const PairEnergy& energy, const Eigen::Vector3d& start_scaled,
                                     const RelaxOptions& opt) {
  using C = detail::PolarCoordinates<N>;
  using Vec = typename C::Vec;
  using Mat = typename C::Mat;
  auto evaluate = [&](const Vec& q, Vec& grad, Eigen::Vector3d& g3) {
    const double e = energy.scaled_energy_and_gradient(C::separation(q), g3);
    grad = C::gradient(q, g3);
    return e;
  };
  Vec q = C::from_separation(start_scaled);
  Vec g;
  Eigen::Vector3d g3;
  double e = evaluate(q, g, g3);
  Vec direction = Vec::Zero();
  Vec preconditioned_old = Vec::Zero();
  Vec g_old = Vec::Zero();
  RelaxResult result;
  double bracket = 0.0;  // width of the verified bracket, units of R
  bool restart = true;   // start (again) along the preconditioned gradient
  for (int it = 0; it < opt.max_iterations; ++it) {
    result.iterations = it;
    if (g.template lpNorm<Eigen::Infinity>() < opt.gradient_tolerance) {
      result.converged = true;
      break;
    }
    const Mat hessian = C::hessian(q, g3, energy.scaled_hessian(C::separation(q)));
    const Vec curvature = hessian.diagonal();
    const Vec inverse = Vec::Ones().cwiseQuotient(curvature.cwiseAbs().cwiseMax(1e-10));
    const Vec preconditioned = inverse.cwiseProduct(g);
    if (detail::gradient_at_resolution(q, g, curvature, e, opt.gradient_tolerance,
                                       opt.step_tolerance)) {
      // Verification only (the iteration stays conjugate gradients): the full Newton step
      // where the Hessian is positive definite, so coupled coordinates are probed together.
      const Eigen::LDLT<Mat> ldlt(hessian);
      const bool definite =
          ldlt.info() == Eigen::Success && ldlt.isPositive() && ldlt.vectorD().minCoeff() > 1e-10;
      const Vec step = definite ? Vec(-ldlt.solve(g)) : Vec(-preconditioned);
      const detail::Probe<N> probe =
          detail::probe_minimum<N>(q, g, step, opt.gradient_tolerance, evaluate);
      if (probe.brackets) {
        bracket = (C::separation(probe.q) - C::separation(q)).norm();
        result.converged = true;
        break;
      }
      if (probe.energy <= e + detail::energy_roundoff(e)) {  // past a curvature jump: go on
        q = probe.q;  // from the probe, along its own gradient (as in Newton's iteration)
        g = probe.gradient;
        g3 = probe.gradient3;
        e = probe.energy;
        restart = true;
        result.iterations = it + 1;
        continue;
      }
    }
    // PR+ with the preconditioner; restart along the preconditioned gradient when conjugacy
    // is lost (or on the first iteration).
    const double beta =
        restart ? 0.0
                : std::max(0.0, preconditioned.dot(g - g_old) / preconditioned_old.dot(g_old));
    restart = false;
    direction = -preconditioned + beta * direction;
    double slope0 = g.dot(direction);
    if (!(slope0 < 0.0)) {
      direction = -preconditioned;
      slope0 = g.dot(direction);
    }
    double e_trial = 0.0;
    Vec g_trial;
    Eigen::Vector3d g3_trial;
    const double alpha =
        line_minimum<N>(evaluate, q, e, direction, slope0, opt, e_trial, g_trial, g3_trial);
    const Vec q_new = q + alpha * direction;
    if (e_trial > e + detail::energy_roundoff(e) || q_new == q) {
      // No progress along the line: converged only if the minimum lies within a few ulps of q.
      result.converged =
          detail::minimum_next_to<N>(q, g, opt.gradient_tolerance, evaluate, bracket);
      break;
    }
    q = q_new;
    g_old = g;
    preconditioned_old = preconditioned;
    g = g_trial;
    g3 = g3_trial;
    e = e_trial;
    result.iterations = it + 1;
  }
  if (!result.converged) {
    result.converged = g.template lpNorm<Eigen::Infinity>() < opt.gradient_tolerance;
  }
  result.separation = C::separation(q) * energy.length_scale();
  // A verified bracket bounds the error; otherwise the Newton step estimates it (it
  // overstates it where the curvature at q is not the minimum's, hence not both).
  result.position_error = (bracket > 0.0 ? bracket : detail::newton_distance<N>(energy, q, g, g3)) *
                          energy.length_scale();
  return result;
}

template RelaxResult relax_conjugate_gradient<1>(const PairEnergy&, const Eigen::Vector3d&,
                                                 const RelaxOptions&);
template RelaxResult relax_conjugate_gradient<2>(const PairEnergy&, const Eigen::Vector3d&,
                                                 const RelaxOptions&);

}  // namespace mresim::pair
