#include "mresim/magnetism/froehlich_kennelly.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "mresim/core/constants.hpp"

namespace mresim::magnetism {

namespace {

void check_parameters(const char* who, double chi, double Ms) {
  if (!(std::isfinite(chi) && chi >= 0.0)) {
    throw std::invalid_argument(std::string(who) + ": susceptibility must be finite and >= 0");
  }
  if (!(std::isfinite(Ms) && Ms > 0.0)) {
    throw std::invalid_argument(std::string(who) +
                                ": saturation magnetization must be finite and > 0");
  }
}

}  // namespace

Eigen::Vector3d froehlich_kennelly(const Eigen::Vector3d& H, double chi0, double Ms) {
  check_parameters("froehlich_kennelly", chi0, Ms);
  // Eq. 1.5: M = Ms chi0 H / (Ms + chi0 |H|).
  return (Ms * chi0 / (Ms + chi0 * H.norm())) * H;
}

double froehlich_kennelly(double H, double chi0, double Ms) {
  check_parameters("froehlich_kennelly", chi0, Ms);
  return Ms * chi0 * H / (Ms + chi0 * std::abs(H));  // eq. 1.5
}

double froehlich_kennelly_derivative(double H, double chi0, double Ms) {
  check_parameters("froehlich_kennelly_derivative", chi0, Ms);
  const double denominator = Ms + chi0 * std::abs(H);
  return Ms * Ms * chi0 / (denominator * denominator);  // d/dH of eq. 1.5
}

Eigen::Matrix3d froehlich_kennelly_jacobian(const Eigen::Vector3d& H, double chi0, double Ms) {
  check_parameters("froehlich_kennelly_jacobian", chi0, Ms);
  const double h = H.norm();
  const double denominator = Ms + chi0 * h;
  const double secant = Ms * chi0 / denominator;  // f = |M| / |H| of eq. 1.5
  Eigen::Matrix3d jacobian = secant * Eigen::Matrix3d::Identity();
  if (h > 0.0) {
    const Eigen::Vector3d u = H / h;
    // d(f(h) H)/dH = f I + f'(h) h u u^T with f'(h) h = -f chi0 h / (Ms + chi0 h).
    jacobian -= (secant * chi0 * h / denominator) * (u * u.transpose());
  }
  return jacobian;
}

Eigen::Vector3d linear_saturable(const Eigen::Vector3d& H, double chi, double Ms) {
  check_parameters("linear_saturable", chi, Ms);
  const double h = H.norm();
  if (chi * h <= Ms) return chi * H;  // eq. 1.4
  return (Ms / h) * H;                // |M| clipped to Ms, still collinear with H
}

double linear_saturable(double H, double chi, double Ms) {
  check_parameters("linear_saturable", chi, Ms);
  return std::clamp(chi * H, -Ms, Ms);
}

Eigen::Matrix3d linear_saturable_jacobian(const Eigen::Vector3d& H, double chi, double Ms) {
  check_parameters("linear_saturable_jacobian", chi, Ms);
  const double h = H.norm();
  if (chi * h <= Ms) return chi * Eigen::Matrix3d::Identity();
  const Eigen::Vector3d u = H / h;
  return (Ms / h) * (Eigen::Matrix3d::Identity() - u * u.transpose());
}

MagnetizationCurve froehlich_kennelly_loop(double chi0, double Ms, double b_max, double b_step) {
  check_parameters("froehlich_kennelly_loop", chi0, Ms);
  MagnetizationCurve curve;
  for (const SweepPoint& point : major_loop_sweep(b_max, b_step)) {
    const double H = point.b_tesla / kMu0;  // applied field B = mu0 H
    curve.b_tesla.push_back(point.b_tesla);
    curve.m_over_ms.push_back(froehlich_kennelly(H, chi0, Ms) / Ms);
    curve.branch.push_back(point.branch);
  }
  return curve;
}

}  // namespace mresim::magnetism
