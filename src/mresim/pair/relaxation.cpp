#include "mresim/pair/relaxation.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

namespace mresim::pair {
namespace {

// Minimises over N coordinates q that map to the separation d = embed(q) (in units of R).
template <int N, class Embed, class Project>
RelaxResult minimise(const PairEnergy& energy, const Eigen::Vector3d& start_scaled, Embed embed,
                     Project project, const RelaxOptions& opt) {
  using Vec = Eigen::Matrix<double, N, 1>;
  using Mat = Eigen::Matrix<double, N, N>;
  auto evaluate = [&](const Vec& q, Vec& grad) {
    Eigen::Vector3d g3;
    const double e = energy.scaled_energy_and_gradient(embed(q), g3);
    grad = project(g3);
    return e;
  };

  Vec q = project(start_scaled);
  Vec g;
  double e = evaluate(q, g);
  RelaxResult result;
  // Finite-difference step for the Hessian: far below the narrowest feature of the energy
  // (the default tanh penalty varies over ~6e-8 R) yet far above round-off.
  constexpr double kHessianStep = 1e-9;
  for (int it = 0; it < opt.max_iterations; ++it) {
    result.iterations = it;
    if (g.template lpNorm<Eigen::Infinity>() < opt.gradient_tolerance) {
      result.converged = true;
      break;
    }
    Mat hessian;
    for (int i = 0; i < N; ++i) {
      Vec qp = q, qm = q, gp, gm;
      qp(i) += kHessianStep;
      qm(i) -= kHessianStep;
      evaluate(qp, gp);
      evaluate(qm, gm);
      hessian.col(i) = (gp - gm) / (2.0 * kHessianStep);
    }
    hessian = 0.5 * (hessian + hessian.transpose()).eval();

    Eigen::SelfAdjointEigenSolver<Mat> eig(hessian);
    Vec step = Vec::Zero();
    const double floor = 1e-12 + 1e-9 * eig.eigenvalues().cwiseAbs().maxCoeff();
    for (int i = 0; i < N; ++i) {
      const Vec v = eig.eigenvectors().col(i);
      const double lambda = eig.eigenvalues()(i);
      const double gv = v.dot(g);
      // Negative (or vanishing) curvature: move the full trust length downhill along v.
      step -= (lambda > floor ? gv / lambda : std::copysign(opt.max_step, gv)) * v;
    }
    const double length = step.norm();
    // At a stiff wall (the tanh penalty) the gradient cannot fall below tolerance because the
    // position itself is resolved only to round-off; a vanishing Newton step at positive
    // curvature is then the convergence test.
    if (eig.eigenvalues().minCoeff() > floor && length < opt.step_tolerance * (1.0 + q.norm())) {
      result.converged = true;
      break;
    }
    if (length > opt.max_step) step *= opt.max_step / length;
    double slope = g.dot(step);
    if (slope >= 0.0) {  // not a descent direction (Hessian noise): fall back to the gradient
      step = -g * std::min(1.0, opt.max_step / g.norm());
      slope = g.dot(step);
    }

    bool accepted = false;
    for (double t = 1.0; t > 1e-12; t *= 0.5) {
      Vec q_new = q + t * step;
      Vec g_new;
      const double e_new = evaluate(q_new, g_new);
      const bool armijo = e_new <= e + 1e-4 * t * slope;
      // At convergence energy differences fall below round-off; a step that keeps the energy
      // within round-off and reduces the gradient is still progress.
      const bool roundoff = std::abs(e_new - e) <= 1e-14 * (1.0 + std::abs(e)) &&
                            g_new.norm() < g.norm();
      if (armijo || roundoff) {
        q = q_new;
        g = g_new;
        e = e_new;
        accepted = true;
        break;
      }
    }
    if (!accepted) {
      result.converged = g.template lpNorm<Eigen::Infinity>() < 1e3 * opt.gradient_tolerance;
      break;
    }
    result.iterations = it + 1;
  }
  if (!result.converged) result.converged = g.template lpNorm<Eigen::Infinity>() < opt.gradient_tolerance;
  result.separation = embed(q) * energy.length_scale();
  return result;
}

}  // namespace

RelaxResult relax(const PairEnergy& energy, SpringModel model, const Eigen::Vector3d& start,
                  const RelaxOptions& options) {
  const Eigen::Vector3d scaled = start / energy.length_scale();
  if (model == SpringModel::single) {
    auto embed = [](const Eigen::Matrix<double, 1, 1>& q) { return Eigen::Vector3d(q(0), 0, 0); };
    auto project = [](const Eigen::Vector3d& v) { return Eigen::Matrix<double, 1, 1>(v.x()); };
    return minimise<1>(energy, scaled, embed, project, options);
  }
  auto identity = [](const Eigen::Vector3d& v) { return v; };
  return minimise<3>(energy, scaled, identity, identity, options);
}

}  // namespace mresim::pair
