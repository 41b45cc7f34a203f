#include "mresim/pair/relaxation.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>

namespace mresim::pair {
namespace {

// Relaxation coordinates q, mapped to the separation d (units of R).
// Single-spring: q = (S), d = S x (the axis cannot rotate).
// Three-spring:  q = (S, theta), d = S (cos theta, 0, sin theta). The field lies in the xz-plane
// with the zero-field axis, so by mirror symmetry the pair stays in that plane. Polar
// coordinates separate the overlap penalty, which is ~1e13 times stiffer than anything else
// and depends on S only, from the soft rotation, so a clustered pair can roll towards the field
// without a Cartesian step leaving the contact sphere.
template <int N>
struct PolarCoordinates {
  using Vec = Eigen::Matrix<double, N, 1>;
  using Mat = Eigen::Matrix<double, N, N>;

  static Eigen::Vector3d radial(const Vec& q) {
    const double t = N == 2 ? q(N - 1) : 0.0;
    return {std::cos(t), 0.0, std::sin(t)};
  }
  static Eigen::Vector3d tangent(const Vec& q) {
    const double t = N == 2 ? q(N - 1) : 0.0;
    return {-std::sin(t), 0.0, std::cos(t)};
  }
  static Vec from_separation(const Eigen::Vector3d& d) {
    Vec q;
    q(0) = d.norm();
    if constexpr (N == 2) q(1) = std::atan2(d.z(), d.x());
    return q;
  }
  static Eigen::Vector3d separation(const Vec& q) { return q(0) * radial(q); }
  // Chain rule: dE/dS = n.g, dE/dtheta = S t.g.
  static Vec gradient(const Vec& q, const Eigen::Vector3d& g) {
    Vec out;
    out(0) = radial(q).dot(g);
    if constexpr (N == 2) out(1) = q(0) * tangent(q).dot(g);
    return out;
  }
  // Second derivatives with d_theta d = S t and d_theta^2 d = -S n, d_S d_theta d = t.
  static Mat hessian(const Vec& q, const Eigen::Vector3d& g, const Eigen::Matrix3d& h) {
    const Eigen::Vector3d n = radial(q);
    Mat out;
    out(0, 0) = n.dot(h * n);
    if constexpr (N == 2) {
      const Eigen::Vector3d t = tangent(q);
      const double s = q(0);
      out(0, 1) = out(1, 0) = s * n.dot(h * t) + t.dot(g);
      out(1, 1) = s * s * t.dot(h * t) - s * n.dot(g);
    }
    return out;
  }
};

template <int N>
RelaxResult minimise(const PairEnergy& energy, const Eigen::Vector3d& start_scaled,
                     const RelaxOptions& opt) {
  using C = PolarCoordinates<N>;
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
    const double energy_resolution = 8.0 * std::numeric_limits<double>::epsilon() * (1.0 + std::abs(e));
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
    for (double t = 1.0; t > 1e-14; t *= 0.5) {
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
  return model == SpringModel::single ? minimise<1>(energy, scaled, options)
                                      : minimise<2>(energy, scaled, options);
}

}  // namespace mresim::pair
