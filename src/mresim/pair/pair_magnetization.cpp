#include "mresim/pair/pair_magnetization.hpp"

#include <cmath>
#include <stdexcept>

namespace mresim::pair {
namespace {

// Saturated moment on the unit circle spanned by the pair axis n and the perpendicular field
// direction p: m = cos(phi) n + sin(phi) p minimises g = -m.h - m.D m / 2, i.e.
// g(phi) = -(h_n cos phi + h_p sin phi) - (3a/2) cos^2 phi  (+ const), a = 1/(3 S^3).
// The minimum lies between the field direction and the nearer pole of the axis, where g'
// changes sign, so a safeguarded Newton iteration on g' is guaranteed to converge.
double saturated_angle(double h_n, double h_p, double a) {
  const double phi_field = std::atan2(h_p, h_n);  // in [0, pi] because h_p >= 0
  auto dg = [&](double phi) {
    return h_n * std::sin(phi) - h_p * std::cos(phi) + 1.5 * a * std::sin(2.0 * phi);
  };
  auto d2g = [&](double phi) {
    return h_n * std::cos(phi) + h_p * std::sin(phi) + 3.0 * a * std::cos(2.0 * phi);
  };
  double lo = 0.0;
  double hi = phi_field;
  if (phi_field > 0.5 * std::acos(-1.0)) {
    lo = phi_field;
    hi = std::acos(-1.0);
  }
  if (hi - lo < 1e-15) return phi_field;
  double phi = phi_field;
  for (int it = 0; it < 100; ++it) {
    const double g1 = dg(phi);
    if (std::abs(g1) < 1e-15) break;
    // Keep the bracket [lo, hi] with dg(lo) <= 0 <= dg(hi).
    if (g1 > 0.0) {
      hi = phi;
    } else {
      lo = phi;
    }
    const double curvature = d2g(phi);
    double next = curvature > 0.0 ? phi - g1 / curvature : 0.5 * (lo + hi);
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    if (std::abs(next - phi) < 1e-15) break;
    phi = next;
  }
  return phi;
}

}  // namespace

Eigen::Matrix3d dipole_coupling(const Eigen::Vector3d& d_over_r) {
  const double s = d_over_r.norm();
  const Eigen::Vector3d n = d_over_r / s;
  const double a = 1.0 / (3.0 * s * s * s);
  return a * (3.0 * n * n.transpose() - Eigen::Matrix3d::Identity());
}

PairMagnetization solve_pair_magnetization(const Eigen::Vector3d& d_over_r,
                                           const Eigen::Vector3d& reduced_field,
                                           double susceptibility) {
  PairMagnetization result;
  const double s = d_over_r.norm();
  if (!(s > 0.0)) throw std::invalid_argument("pair magnetization: coincident sphere centres");
  const Eigen::Vector3d n = d_over_r / s;
  const double a = 1.0 / (3.0 * s * s * s);
  const double h_n = reduced_field.dot(n);
  const Eigen::Vector3d h_perp_vec = reduced_field - h_n * n;
  const double h_p = h_perp_vec.norm();
  const Eigen::Vector3d p = h_p > 0.0 ? Eigen::Vector3d(h_perp_vec / h_p) : Eigen::Vector3d::Zero();

  // Eigen-decomposition of (I/chi - D): 1/chi - 2a along n, 1/chi + a across it.
  const double inv_chi = 1.0 / susceptibility;
  const double stiff_axial = inv_chi - 2.0 * a;
  const double stiff_transverse = inv_chi + a;
  if (stiff_axial > 0.0) {
    const double m_n = h_n / stiff_axial;
    const double m_p = h_p / stiff_transverse;
    if (m_n * m_n + m_p * m_p <= 1.0) {
      result.m = m_n * n + m_p * p;
      return result;
    }
  }
  // Saturated (or, for chi >= 3 S^3 / 2, the unsaturated law has no stable solution): the
  // minimiser lies on |m| = 1.
  if (h_n == 0.0 && h_p == 0.0) {
    result.m = n;  // zero field with an unstable pair: the axis is the preferred direction
  } else {
    const double phi = saturated_angle(h_n, h_p, a);
    result.m = std::cos(phi) * n + std::sin(phi) * p;
  }
  result.saturated = true;
  return result;
}

}  // namespace mresim::pair
