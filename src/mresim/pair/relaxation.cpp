#include "mresim/pair/relaxation.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>

#include "mresim/pair/relaxation_coordinates.hpp"

namespace mresim::pair {
namespace {

template <int N>
RelaxResult newton(const PairEnergy& energy, const Eigen::Vector3d& start_scaled,
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
  RelaxResult result;
  bool previous_at_resolution = false;
  for (int it = 0; it < opt.max_iterations; ++it) {
    result.iterations = it;
    if (g.template lpNorm<Eigen::Infinity>() < opt.gradient_tolerance) {
      result.converged = true;
      break;
    }
    const Mat hessian = C::hessian(q, g3, energy.scaled_hessian(C::separation(q)));
    Eigen::SelfAdjointEigenSolver<Mat> eig(hessian);
    // The Hessian is accurate to ~1e-10 (its magnetic part is finite-differenced), so smaller
    // curvatures are treated as flat.
    const double floor = 1e-10 + 1e-15 * eig.eigenvalues().cwiseAbs().maxCoeff();
    Vec step = Vec::Zero();
    for (int i = 0; i < N; ++i) {
      const Vec v = eig.eigenvectors().col(i);
      const double lambda = eig.eigenvalues()(i);
      const double gv = v.dot(g);
      // Negative (or vanishing) curvature: move the full trust length downhill along v.
      step -= (lambda > floor ? gv / lambda : std::copysign(opt.max_step, gv)) * v;
    }
    const double length = step.norm();
    // A coordinate is converged when its gradient is below what the arithmetic can resolve:
    // at a stiff wall, the gradient that a displacement of step_tolerance produces; along a
    // soft direction, the gradient whose Newton step changes the energy by less than its
    // round-off. (A small Newton step alone is not enough: at the WCA cut-off the curvature
    // jumps, and the step from inside is tiny although the minimum lies outside.)
    const double energy_resolution =
        8.0 * std::numeric_limits<double>::epsilon() * (1.0 + std::abs(e));
    bool at_resolution = eig.eigenvalues().minCoeff() > floor;
    for (int i = 0; i < N && at_resolution; ++i) {
      const double curvature = std::abs(hessian(i, i));
      at_resolution = std::abs(g(i)) <= opt.gradient_tolerance +
                                            opt.step_tolerance * (1.0 + q.norm()) * curvature +
                                            std::sqrt(2.0 * curvature * energy_resolution);
    }
    // Require it at two successive iterates: at a kink (the WCA cut-off) the point just across
    // has a different curvature and fails the test there.
    if (at_resolution && previous_at_resolution) {
      result.converged = true;
      break;
    }
    previous_at_resolution = at_resolution;
    if (length > opt.max_step) step *= opt.max_step / length;
    double slope = g.dot(step);
    if (slope >= 0.0) {  // not a descent direction (round-off): fall back to the gradient
      step = -g * std::min(1.0, opt.max_step / g.norm());
      slope = g.dot(step);
    }

    // Length of the Newton step a gradient asks for, so that a stiff coordinate's round-off
    // noise does not mask progress along a soft one.
    auto newton_length = [&](const Vec& grad) {
      return (grad.array() / hessian.diagonal().array().abs().max(floor)).matrix().norm();
    };
    bool accepted = false;
    double t = 1.0;
    for (int halving = 0; halving < 47; ++halving, t *= 0.5) {  // down to t ~ 1e-14
      const Vec q_new = q + t * step;
      Vec g_new;
      Eigen::Vector3d g3_new;
      const double e_new = evaluate(q_new, g_new, g3_new);
      const bool armijo = e_new <= e + 1e-4 * t * slope;
      // Near convergence energy differences fall below round-off; a step that keeps the energy
      // within round-off and reduces the gradient is still progress.
      const bool roundoff = std::abs(e_new - e) <= 1e-14 * (1.0 + std::abs(e)) &&
                            newton_length(g_new) < newton_length(g);
      if (armijo || roundoff) {
        if (q_new == q) {  // the step is below the resolution of q: nothing left to gain
          result.converged = at_resolution;
          break;
        }
        q = q_new;
        g = g_new;
        g3 = g3_new;
        e = e_new;
        accepted = true;
        break;
      }
    }
    result.iterations = it + 1;
    if (!accepted || result.converged) break;
  }
  if (!result.converged) {
    result.converged = g.template lpNorm<Eigen::Infinity>() < opt.gradient_tolerance;
  }
  result.separation = C::separation(q) * energy.length_scale();
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
