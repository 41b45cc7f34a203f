#include "mresim/pair/relaxation.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>

#include "mresim/pair/relaxation_coordinates.hpp"

namespace mresim::pair {
namespace {

template <int N>
struct NewtonStep {
  using Mat = typename detail::PolarCoordinates<N>::Mat;
  using Vec = typename detail::PolarCoordinates<N>::Vec;
  Mat hessian;
  Vec step;
  double floor = 0.0;
  bool at_resolution = false;  // the step is below what the line search can resolve
};

// Saddle-free Newton step at q: negative or vanishing curvature moves the full trust length
// downhill. It is at resolution when every coordinate's gradient is below what the arithmetic
// can resolve: at a stiff wall, the gradient that a displacement of step_tolerance produces;
// along a soft direction, the gradient whose Newton step changes the energy by less than its
// round-off. (That alone is not convergence: see detail::probe_minimum.)
template <int N, typename Vec>
NewtonStep<N> newton_step(const PairEnergy& energy, const Vec& q, const Vec& g,
                          const Eigen::Vector3d& g3, double e, const RelaxOptions& opt) {
  using C = detail::PolarCoordinates<N>;
  NewtonStep<N> out;
  out.hessian = C::hessian(q, g3, energy.scaled_hessian(C::separation(q)));
  Eigen::SelfAdjointEigenSolver<typename NewtonStep<N>::Mat> eig(out.hessian);
  // The Hessian is accurate to ~1e-10 (its magnetic part is finite-differenced), so smaller
  // curvatures are treated as flat.
  out.floor = 1e-10 + 1e-15 * eig.eigenvalues().cwiseAbs().maxCoeff();
  out.step = Vec::Zero();
  for (int i = 0; i < N; ++i) {
    const Vec v = eig.eigenvectors().col(i);
    const double lambda = eig.eigenvalues()(i);
    const double gv = v.dot(g);
    out.step -= (lambda > out.floor ? gv / lambda : std::copysign(opt.max_step, gv)) * v;
  }
  out.at_resolution = eig.eigenvalues().minCoeff() > out.floor &&
                      detail::gradient_at_resolution(q, g, Vec(out.hessian.diagonal()), e,
                                                     opt.gradient_tolerance, opt.step_tolerance);
  return out;
}

// Armijo backtracking along the (capped) Newton step; updates q, g, g3, e and returns whether a
// step was taken. Steps are capped at max_step and the energy never rises, so a pair cannot
// tunnel through a penalty.
template <int N, typename Evaluate, typename Vec>
bool line_search(const Evaluate& evaluate, const NewtonStep<N>& newton, const RelaxOptions& opt,
                 Vec& q, Vec& g, Eigen::Vector3d& g3, double& e) {
  Vec step = newton.step;
  const double length = step.norm();
  if (length > opt.max_step) step *= opt.max_step / length;
  double slope = g.dot(step);
  if (slope >= 0.0) {  // not a descent direction (round-off): fall back to the gradient
    step = -g * std::min(1.0, opt.max_step / g.norm());
    slope = g.dot(step);
  }
  // Length of the Newton step a gradient asks for, so that a stiff coordinate's round-off
  // noise does not mask progress along a soft one.
  auto newton_length = [&](const Vec& grad) {
    return (grad.array() / newton.hessian.diagonal().array().abs().max(newton.floor))
        .matrix()
        .norm();
  };
  double t = 1.0;
  for (int halving = 0; halving < 47; ++halving, t *= 0.5) {  // down to t ~ 1e-14
    const Vec q_new = q + t * step;
    if (q_new == q) return false;  // the step is below the resolution of q
    Vec g_new;
    Eigen::Vector3d g3_new;
    const double e_new = evaluate(q_new, g_new, g3_new);
    const bool armijo = e_new <= e + 1e-4 * t * slope;
    // Near convergence energy differences fall below round-off; a step that keeps the energy
    // within round-off and reduces the gradient is still progress.
    const bool roundoff = std::abs(e_new - e) <= 1e-14 * (1.0 + std::abs(e)) &&
                          newton_length(g_new) < newton_length(g);
    if (armijo || roundoff) {
      q = q_new;
      g = g_new;
      g3 = g3_new;
      e = e_new;
      return true;
    }
  }
  return false;
}

// Newton step along the rotation alone, for a three-spring pair resting on the WCA wall. There
// the saddle-free step fails: at q (on the cut-off, a few ulps from the radial minimum) the
// radial curvature is the outside's, negative with the attraction, so the step heads into the
// wall along an eigenvector that mixes S and theta, and every fraction of it raises the energy.
// The radial coordinate is then at its minimum to the ulp (its gradient changes sign within a
// few ulps inwards) but the rotation may still be off by a few 1e-4 rad near a critical field:
// the pair must roll along the contact sphere at fixed S. (Not a fold: in the Fig. 2.9 cells
// that stopped here the minimum exists on the wall, and rolling reaches it with the critical
// fields unchanged; docs/two-dipole-model.md.) Returns whether a step was taken.
template <int N, typename Evaluate, typename Vec>
bool roll_on_wall(const Evaluate& evaluate, const NewtonStep<N>& newton, const RelaxOptions& opt,
                  Vec& q, Vec& g, Eigen::Vector3d& g3, double& e) {
  if constexpr (N == 1) {
    return false;
  } else {
    if (std::abs(g(1)) < opt.gradient_tolerance) return false;  // nothing left to roll
    bool pinned = false;  // the radial gradient vanishes or changes sign within 256 ulps
    for (const double ulps : {4.0, 32.0, 256.0}) {
      const detail::Probe<N> p =
          detail::probe_minimum<N>(q, g, Vec::Zero(), opt.gradient_tolerance, evaluate, ulps);
      pinned =
          pinned || std::abs(p.gradient(0)) < opt.gradient_tolerance || g(0) * p.gradient(0) <= 0.0;
    }
    if (!pinned) return false;
    NewtonStep<N> rolling = newton;
    const double c = newton.hessian(1, 1);
    rolling.step = Vec(0.0, c > newton.floor ? -g(1) / c : -std::copysign(opt.max_step, g(1)));
    // Radial row and column out of the line search's progress measure (S does not move).
    rolling.hessian(0, 1) = rolling.hessian(1, 0) = 0.0;
    rolling.hessian(0, 0) = std::numeric_limits<double>::infinity();
    return line_search<N>(evaluate, rolling, opt, q, g, g3, e);
  }
}

template <int N>
RelaxResult newton(const PairEnergy& energy, const Eigen::Vector3d& start_scaled,
                   const RelaxOptions& opt) {
  using C = detail::PolarCoordinates<N>;
  using Vec = typename C::Vec;
  auto evaluate = [&](const Vec& q, Vec& grad, Eigen::Vector3d& g3) {
    const double e = energy.scaled_energy_and_gradient(C::separation(q), g3);
    grad = C::gradient(q, g3);
    return e;
  };

  Vec q = C::from_separation(start_scaled);
  Vec g;
  Eigen::Vector3d g3;
  double e = evaluate(q, g, g3);
  RelaxResult result;
  double bracket = 0.0;  // width of the verified bracket, units of R
  for (int it = 0; it < opt.max_iterations; ++it) {
    result.iterations = it;
    if (g.template lpNorm<Eigen::Infinity>() < opt.gradient_tolerance) {
      result.converged = true;
      break;
    }
    const Vec q_before = q;
    const NewtonStep<N> newton = newton_step<N>(energy, q, g, g3, e, opt);
    result.iterations = it + 1;
    if (newton.at_resolution) {
      const detail::Probe<N> probe =
          detail::probe_minimum<N>(q, g, newton.step, opt.gradient_tolerance, evaluate);
      if (probe.brackets) {  // finish on the Newton point, the best estimate inside the bracket
        Vec g_end;
        Eigen::Vector3d g3_end;
        const Vec q_end = q + newton.step;
        if (q_end != q && evaluate(q_end, g_end, g3_end) <= e + detail::energy_roundoff(e)) {
          q = q_end;
          g = g_end;
          g3 = g3_end;
        }
        bracket = (C::separation(probe.q) - C::separation(q_before)).norm();
        result.converged = true;
        break;
      }
      // The minimum lies beyond the probe (a curvature jump or a wall's tail). The gradient
      // kept its sign, so the energy fell, if below its round-off: move on from there.
      if (probe.energy <= e + detail::energy_roundoff(e)) {
        q = probe.q;
        g = probe.gradient;
        g3 = probe.gradient3;
        e = probe.energy;
        continue;
      }
    }
    if (!line_search<N>(evaluate, newton, opt, q, g, g3, e)) {
      if (roll_on_wall<N>(evaluate, newton, opt, q, g, g3, e)) continue;
      // No step is accepted: the minimum may lie within a few ulps of q where the curvature
      // at q (negative just past the WCA's edge) does not describe it; verify that.
      result.converged =
          detail::minimum_next_to<N>(q, g, opt.gradient_tolerance, evaluate, bracket);
      break;
    }
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

}  // namespace

RelaxResult relax(const PairEnergy& energy, SpringModel model, const Eigen::Vector3d& start,
                  const RelaxOptions& options) {
  const Eigen::Vector3d scaled = start / energy.length_scale();
  if (options.method == RelaxMethod::conjugate_gradient) {
    return model == SpringModel::single ? relax_conjugate_gradient<1>(energy, scaled, options)
                                        : relax_conjugate_gradient<2>(energy, scaled, options);
  }
  return model == SpringModel::single ? newton<1>(energy, scaled, options)
                                      : newton<2>(energy, scaled, options);
}

}  // namespace mresim::pair
