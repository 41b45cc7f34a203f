#include "mresim/mess_analysis/modulus_fit.hpp"

#include <Eigen/Core>
#include <Eigen/QR>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace mresim::mess_analysis {

namespace {

// Number of leading points kept by the split rule of modulus_fit.hpp. The increments of a
// parabola sampled at equally spaced strains grow; the first point reached by a smaller
// increment than the one before it marks the kink (clustering, reference-notes.md section 18)
// and is cut together with everything after it. A jump up (a larger increment) is not a kink.
std::size_t points_before_kink(const std::vector<double>& u) {
  for (std::size_t i = 2; i < u.size(); ++i) {
    const double previous = u[i - 1] - u[i - 2];
    const double increment = u[i] - u[i - 1];
    if (increment < previous) return i;  // keep points 0 .. i-1
  }
  return u.size();
}

}  // namespace

QuadraticFit fit_energy_density(const std::vector<double>& strain,
                                const std::vector<double>& energy_density) {
  if (strain.size() != energy_density.size()) {
    throw std::invalid_argument("fit_energy_density: strain and energy density differ in size");
  }
  QuadraticFit fit;
  // The zero-strain point above the next one is dropped (reference-notes.md section 18).
  fit.first =
      energy_density.size() >= 3 && strain[0] == 0.0 && energy_density[1] < energy_density[0] ? 1
                                                                                              : 0;
  const std::vector<double> x_fit(strain.begin() + static_cast<std::ptrdiff_t>(fit.first),
                                  strain.end());
  const std::vector<double> u_fit(energy_density.begin() + static_cast<std::ptrdiff_t>(fit.first),
                                  energy_density.end());
  const std::size_t n = x_fit.size();
  const std::size_t kept = points_before_kink(u_fit);
  // Fewer than 3 points before the kink cannot determine a and c with any redundancy; the
  // header's rule then fits the whole curve.
  if (kept < n && kept >= 3) {
    fit.points = kept;
    fit.split = true;
  } else {
    fit.points = n;
  }

  // Two unknowns need two distinct x^2; equal |x| (e.g. +-gamma only) leaves a undetermined.
  bool distinct = false;
  for (std::size_t i = 1; i < fit.points && !distinct; ++i) {
    distinct = std::abs(x_fit[i]) != std::abs(x_fit[0]);
  }
  if (!distinct) return fit;

  // u = a (x^2/2) + c is linear in (a, c). Column-pivoted Householder QR works on the design
  // matrix directly instead of squaring its condition number as the normal equations would
  // (x^2/2 ~ 1e-4 next to a column of ones for typical strains). The original used a
  // nonlinear least-squares routine on the same model (Section 4.2.8); the minimum is the same.
  const auto m = static_cast<Eigen::Index>(fit.points);
  Eigen::MatrixX2d design(m, 2);
  Eigen::VectorXd u(m);
  for (Eigen::Index i = 0; i < m; ++i) {
    const double x = x_fit[static_cast<std::size_t>(i)];
    design(i, 0) = 0.5 * x * x;
    design(i, 1) = 1.0;
    u(i) = u_fit[static_cast<std::size_t>(i)];
  }
  const Eigen::Vector2d coefficients = design.colPivHouseholderQr().solve(u);
  fit.modulus = coefficients(0);
  fit.offset = coefficients(1);
  fit.rms_residual = std::sqrt((design * coefficients - u).squaredNorm() / static_cast<double>(m));
  fit.valid = true;
  return fit;
}

LinearFit fit_stress_strain(const std::vector<double>& strain, const std::vector<double>& stress) {
  if (strain.size() != stress.size()) {
    throw std::invalid_argument("fit_stress_strain: strain and stress differ in size");
  }
  LinearFit fit;
  fit.points = strain.size();
  // Least squares through the origin: the unstrained state carries no stress.
  double se = 0.0;
  double ee = 0.0;
  for (std::size_t i = 0; i < strain.size(); ++i) {
    se += stress[i] * strain[i];
    ee += strain[i] * strain[i];
  }
  if (!(ee > 0.0)) return fit;
  fit.modulus = se / ee;
  double sum_sq = 0.0;
  for (std::size_t i = 0; i < strain.size(); ++i) {
    const double r = stress[i] - fit.modulus * strain[i];
    sum_sq += r * r;
  }
  fit.rms_residual = std::sqrt(sum_sq / static_cast<double>(fit.points));
  fit.valid = true;
  return fit;
}

double mr_effect_percent(double modulus, double reference) {
  // Written so that a NaN reference also gives NaN (reference-notes.md section 18: the MR
  // effect is relative to the modulus at the first field).
  if (!(reference > 0.0)) return std::numeric_limits<double>::quiet_NaN();
  return (modulus / reference - 1.0) * 100.0;
}

}  // namespace mresim::mess_analysis
