#pragma once

#include <Eigen/Core>
#include <cmath>

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

}  // namespace mresim::pair::detail
