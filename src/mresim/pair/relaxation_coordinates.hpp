#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>

#include "mresim/pair/pair_energy.hpp"

// Internal to the relaxation methods (relaxation.cpp, conjugate_gradient.cpp).
namespace mresim::pair::detail {

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

// Distance (units of R) from q to the minimum its diagonal Newton step predicts: the relaxed
// state's position error, against which branch comparisons must not be finer. (Flat or
// negative curvatures count as 1e-10, the Hessian's accuracy.)
template <int N>
double newton_distance(const PairEnergy& energy, const typename PolarCoordinates<N>::Vec& q,
                       const typename PolarCoordinates<N>::Vec& g, const Eigen::Vector3d& g3) {
  using C = PolarCoordinates<N>;
  const typename C::Vec curvature =
      C::hessian(q, g3, energy.scaled_hessian(C::separation(q))).diagonal();
  const typename C::Vec step = -g.cwiseQuotient(curvature.cwiseAbs().cwiseMax(1e-10));
  return (C::separation(q + step) - C::separation(q)).norm();
}

// Round-off of the scaled energy e.
inline double energy_roundoff(double e) {
  return 8.0 * std::numeric_limits<double>::epsilon() * (1.0 + std::abs(e));
}

// Whether every coordinate's gradient is below what the arithmetic can resolve, given the
// curvature of each coordinate: at a stiff wall, the gradient that a displacement of
// step_tolerance |q| produces; along a soft direction, the gradient whose Newton step changes
// the energy by less than its round-off. (Not convergence by itself: see probe_minimum.)
template <typename Vec>
bool gradient_at_resolution(const Vec& q, const Vec& g, const Vec& curvature, double e,
                            double gradient_tolerance, double step_tolerance) {
  for (int i = 0; i < q.size(); ++i) {
    const double c = std::abs(curvature(i));
    if (std::abs(g(i)) > gradient_tolerance + step_tolerance * (1.0 + q.norm()) * c +
                             std::sqrt(2.0 * c * energy_roundoff(e))) {
      return false;
    }
  }
  return true;
}

// Verifies that a minimum lies within `step` of q (a Newton step too small for the line search to
// resolve): the gradient is evaluated at q + 2 step (each coordinate moved at least a few ulps)
// and every coordinate's gradient must vanish or change sign between q and there. A small
// Newton step alone proves nothing where the curvature at q overstates the curvature further
// on: just inside the WCA cut-off (the curvature drops to the springs' outside it) or in the
// exponential tail of the tanh wall, a soft spring's whole force gives a step below 1e-13 R
// although the minimum lies microns away.
template <int N>
struct Probe {
  using Vec = typename PolarCoordinates<N>::Vec;
  Vec q;
  Vec gradient;
  Eigen::Vector3d gradient3;
  double energy = 0.0;
  bool brackets = false;  // the minimum lies between q and the probe, in every coordinate
};

template <int N, typename Evaluate>
Probe<N> probe_minimum(const typename PolarCoordinates<N>::Vec& q,
                       const typename PolarCoordinates<N>::Vec& g,
                       const typename PolarCoordinates<N>::Vec& step, double gradient_tolerance,
                       const Evaluate& evaluate, double least_ulps = 4.0) {
  constexpr double kEps = std::numeric_limits<double>::epsilon();
  Probe<N> p;
  typename PolarCoordinates<N>::Vec delta = 2.0 * step;
  for (int i = 0; i < N; ++i) {
    const double least = least_ulps * kEps * std::max(1.0, std::abs(q(i)));
    if (std::abs(delta(i)) < least && g(i) != 0.0) {
      delta(i) = std::copysign(least, delta(i) != 0.0 ? delta(i) : -g(i));
    }
  }
  p.q = q + delta;
  p.energy = evaluate(p.q, p.gradient, p.gradient3);
  p.brackets = true;
  for (int i = 0; i < N; ++i) {
    const bool vanishes =
        std::abs(g(i)) < gradient_tolerance || std::abs(p.gradient(i)) < gradient_tolerance;
    if (!vanishes && g(i) * p.gradient(i) > 0.0) p.brackets = false;
  }
  return p;
}

// After a failed line search: whether the minimum lies within a few hundred ulps of q, probed
// at growing distances along -g (a curvature at q that misdescribes the next ulps, as at the
// WCA's edge, makes the line search reject every step there).
// `bracket` receives the distance (units of R) from q to the probe that brackets the minimum.
template <int N, typename Evaluate>
bool minimum_next_to(const typename PolarCoordinates<N>::Vec& q,
                     const typename PolarCoordinates<N>::Vec& g, double gradient_tolerance,
                     const Evaluate& evaluate, double& bracket) {
  using C = PolarCoordinates<N>;
  for (const double ulps : {4.0, 32.0, 256.0}) {
    const Probe<N> p = probe_minimum<N>(q, g, C::Vec::Zero(), gradient_tolerance, evaluate, ulps);
    if (p.brackets) {
      bracket = (C::separation(p.q) - C::separation(q)).norm();
      return true;
    }
  }
  return false;
}

}  // namespace mresim::pair::detail
