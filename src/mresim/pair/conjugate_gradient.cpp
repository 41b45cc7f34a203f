#include <algorithm>
#include <cmath>

#include "mresim/pair/relaxation.hpp"
#include "mresim/pair/relaxation_coordinates.hpp"

namespace mresim::pair {

template <int N>
RelaxResult relax_conjugate_gradient(const PairEnergy& energy, const Eigen::Vector3d& start_scaled,
                                     const RelaxOptions& opt) {
  using C = detail::PolarCoordinates<N>;
  using Vec = typename C::Vec;
  auto evaluate = [&](const Vec& q, Vec& grad) {
    Eigen::Vector3d g3;
    const double e = energy.scaled_energy_and_gradient(C::separation(q), g3);
    grad = C::gradient(q, g3);
    return e;
  };

  Vec q = C::from_separation(start_scaled);
  Vec g;
  double e = evaluate(q, g);
  Vec direction = -g;
  RelaxResult result;
  int small_steps = 0;
  bool restarted = false;
  for (int it = 0; it < opt.max_iterations; ++it) {
    result.iterations = it;
    if (g.template lpNorm<Eigen::Infinity>() < opt.gradient_tolerance) {
      result.converged = true;
      break;
    }
    double slope0 = g.dot(direction);
    if (slope0 >= 0.0) {  // lost conjugacy: restart along the gradient
      direction = -g;
      slope0 = g.dot(direction);
    }
    // Bracket a minimum of phi(a) = E(q + a p): grow the trial step until the directional
    // derivative turns positive or the energy rises, then secant/bisect on phi'.
    double lo = 0.0;
    double slope_lo = slope0;
    // First trial: the minimiser of the quadratic through phi'(0) and the curvature probed with
    // a tiny step (capped at 1% of R). The bracket then closes at the first minimum along the
    // line, so a shallow basin near a critical field (a saddle a fraction of a nanometre past
    // the penalty's edge) is not jumped over.
    const double cap = std::min(1.0, 0.04 * opt.max_step / direction.norm());
    const double probe = 1e-9 / direction.norm();
    Vec g_probe;
    evaluate(q + probe * direction, g_probe);
    const double curvature = (g_probe.dot(direction) - slope0) / probe;
    double hi = curvature > 0.0 ? std::min(cap, -slope0 / curvature) : cap;
    Vec g_trial;
    double e_trial = 0.0;
    double slope_hi = 0.0;
    for (int grow = 0; grow < 60; ++grow) {
      e_trial = evaluate(q + hi * direction, g_trial);
      slope_hi = g_trial.dot(direction);
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
      e_trial = evaluate(q + alpha * direction, g_trial);
      const double slope = g_trial.dot(direction);
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
    if (e_trial > e) {
      // No decrease along this direction: restart along the gradient once; if even that fails,
      // the energy is resolved to round-off and q is the minimum.
      if (restarted) {
        result.converged = true;
        break;
      }
      restarted = true;
      direction = -g;
      continue;
    }
    restarted = false;
    const Vec step = alpha * direction;
    small_steps = step.norm() < opt.step_tolerance * (1.0 + q.norm()) ? small_steps + 1 : 0;
    q += step;
    const double beta = std::max(0.0, g_trial.dot(g_trial - g) / g.squaredNorm());  // PR+
    g = g_trial;
    e = e_trial;
    direction = -g + beta * direction;
    result.iterations = it + 1;
    if (small_steps >= 2) {  // the position is resolved to round-off
      result.converged = true;
      break;
    }
  }
  result.separation = C::separation(q) * energy.length_scale();
  return result;
}

template RelaxResult relax_conjugate_gradient<1>(const PairEnergy&, const Eigen::Vector3d&,
                                                 const RelaxOptions&);
template RelaxResult relax_conjugate_gradient<2>(const PairEnergy&, const Eigen::Vector3d&,
                                                 const RelaxOptions&);

}  // namespace mresim::pair
