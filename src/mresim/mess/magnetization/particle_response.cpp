#include "mresim/mess/magnetization/particle_response.hpp"

#include <cmath>
#include <limits>

namespace mresim::magnetism {
namespace {

// Secant s = |m|/|h| and differential susceptibility dm/d|h| at field magnitude h >= 0.
struct Response {
  double secant;
  double differential;
};

Response response(double h, double chi, bool demagnetization) {
  if (!demagnetization) {
    // Eq. 4.55: m = chi h / (1 + chi h), dm/dh = chi / (1 + chi h)^2.
    const double d = 1.0 + chi * h;
    return {chi / d, chi / (d * d)};
  }
  // m = FK(h - m/3) with x = h - m/3 >= 0: m (1 + chi x) = chi x, i.e.
  //   (chi/3) m^2 - B m + chi h = 0,  B = 1 + chi h + chi/3,
  // whose smaller root (the one with m <= 1 and x >= 0) is m = 2 chi h / (B + sqrt(disc)),
  // disc = B^2 - (4/3) chi^2 h = 1 + 2 chi (h + 1/3) + chi^2 (h - 1/3)^2 (a sum of
  // non-negative terms: no cancellation). Implicit differentiation gives
  // dm/dh = chi (1 - m) / sqrt(disc).
  const double b = 1.0 + chi * h + chi / 3.0;
  const double disc =
      1.0 + 2.0 * chi * (h + 1.0 / 3.0) + chi * chi * (h - 1.0 / 3.0) * (h - 1.0 / 3.0);
  const double root = std::sqrt(disc);
  const double secant = 2.0 * chi / (b + root);
  return {secant, chi * (1.0 - secant * h) / root};
}

}  // namespace

Eigen::Vector3d particle_response(const Eigen::Vector3d& h, double chi, bool demagnetization) {
  return response(h.norm(), chi, demagnetization).secant * h;
}

Eigen::Matrix3d particle_response_jacobian(const Eigen::Vector3d& h, double chi,
                                           bool demagnetization) {
  const double norm = h.norm();
  const Response r = response(norm, chi, demagnetization);
  Eigen::Matrix3d jacobian = r.secant * Eigen::Matrix3d::Identity();
  if (norm > 0.0) {
    const Eigen::Vector3d u = h / norm;
    jacobian += (r.differential - r.secant) * (u * u.transpose());
  }
  return jacobian;
}

Eigen::Vector3d particle_response_inverse(const Eigen::Vector3d& m, double chi,
                                          bool demagnetization) {
  const double a = m.norm();
  if (!(a < 1.0)) {
    return Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  }
  // Inverse of eq. 4.55: h = m / (chi (1 - |m|)); the internal field plus m/3 with demag.
  Eigen::Vector3d h = m / (chi * (1.0 - a));
  if (demagnetization) h += m / 3.0;
  return h;
}

Eigen::Matrix3d particle_response_inverse_jacobian(const Eigen::Vector3d& m, double chi,
                                                   bool demagnetization) {
  const double a = m.norm();
  if (!(a < 1.0)) {
    return Eigen::Matrix3d::Constant(std::numeric_limits<double>::infinity());
  }
  const double transverse = 1.0 / (chi * (1.0 - a));
  Eigen::Matrix3d jacobian = transverse * Eigen::Matrix3d::Identity();
  if (a > 0.0) {
    const Eigen::Vector3d u = m / a;
    // Longitudinal: d/da [a / (chi (1 - a))] = 1 / (chi (1 - a)^2).
    jacobian += (transverse * a / (1.0 - a)) * (u * u.transpose());
  }
  if (demagnetization) jacobian += Eigen::Matrix3d::Identity() / 3.0;
  return jacobian;
}

double reduced_self_energy(const Eigen::Vector3d& m, double chi, bool demagnetization) {
  const double a = m.norm();
  if (!(a < 1.0)) return std::numeric_limits<double>::infinity();
  // Eq. 4.76 / (mu0 Ms^2 V): [-M + Ms log(Ms / (Ms - M))] / (chi Ms) = [-a - log(1 - a)] / chi.
  double s = (-a - std::log1p(-a)) / chi;
  if (demagnetization) s += a * a / 6.0;  // demagnetizing energy mu0 V M^2 / 6 (N = 1/3)
  return s;
}

}  // namespace mresim::magnetism
