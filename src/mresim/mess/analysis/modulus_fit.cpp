#include "mresim/mess/analysis/modulus_fit.hpp"

#include <fmt/format.h>

#include <Eigen/Core>
#include <Eigen/QR>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace mresim::mess_analysis {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Number of leading points kept by the split rule of modulus_fit.hpp. The increments of a
// parabola sampled at equally spaced strains grow; the first point reached by a smaller
// increment than the one before it marks the kink (clustering,
// docs/original-code.md#energies-and-moduli) and is cut together with everything after it. A jump
// up (a larger increment) is not a kink.
std::size_t points_before_kink(const std::vector<double>& u) {
  for (std::size_t i = 2; i < u.size(); ++i) {
    const double previous = u[i - 1] - u[i - 2];
    const double increment = u[i] - u[i - 1];
    if (increment < previous) return i;  // keep points 0 .. i-1
  }
  return u.size();
}

// Least-squares a and c of u = a x^2/2 + c over the first `m` points. Column-pivoted
// Householder QR works on the design matrix directly instead of squaring its condition number
// as the normal equations would (x^2/2 ~ 1e-4 next to a column of ones for typical strains).
// The original used a nonlinear least-squares routine on the same model (Section 4.2.8); the
// minimum is the same.
void least_squares(const double* x, const double* u_in, std::size_t m, QuadraticFit& fit) {
  const auto n = static_cast<Eigen::Index>(m);
  Eigen::MatrixX2d design(n, 2);
  Eigen::VectorXd u(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    design(i, 0) = 0.5 * x[i] * x[i];
    design(i, 1) = 1.0;
    u(i) = u_in[i];
  }
  const Eigen::Vector2d coefficients = design.colPivHouseholderQr().solve(u);
  fit.modulus = coefficients(0);
  fit.offset = coefficients(1);
  fit.rms_residual = std::sqrt((design * coefficients - u).squaredNorm() / static_cast<double>(m));
}

// The first condition of the header that the fit over points [first, first + points) fails,
// or "" when it is valid.
std::string quadratic_problem(const std::vector<double>& x, const std::vector<double>& u,
                              const std::vector<bool>& converged, const QuadraticFit& fit,
                              bool distinct) {
  const std::size_t end = fit.first + fit.points;
  for (std::size_t i = fit.first; i < end; ++i) {
    if (!std::isfinite(x[i]) || !std::isfinite(u[i])) {
      return fmt::format("non-finite point at strain {:.6g}", x[i]);
    }
  }
  if (fit.points < kMinFitPoints) {
    return fmt::format("only {} point(s) fitted, at least {} needed", fit.points, kMinFitPoints);
  }
  if (!distinct) return "the fitted strains take one value of |x| only";
  for (std::size_t i = fit.first; i < end; ++i) {
    if (!converged.empty() && !converged[i]) {
      return fmt::format("the step at strain {:.6g} did not converge", x[i]);
    }
  }
  if (fit.first == 0 && x[0] == 0.0) {
    for (std::size_t i = 1; i < end; ++i) {
      if (u[i] < u[0]) {
        return fmt::format(
            "the point at strain {:.6g} lies below the zero-strain state (the energy is not "
            "symmetric about zero strain)",
            x[i]);
      }
    }
  }
  if (!std::isfinite(fit.modulus) || !std::isfinite(fit.offset) ||
      !std::isfinite(fit.rms_residual)) {
    return "non-finite fit";
  }
  if (!(fit.modulus > 0.0)) {
    return fmt::format("curvature {:.6g} is not positive", fit.modulus);
  }
  return {};
}

}  // namespace

QuadraticFit fit_energy_density(const std::vector<double>& strain,
                                const std::vector<double>& energy_density,
                                const FitOptions& options) {
  if (strain.size() != energy_density.size()) {
    throw std::invalid_argument("fit_energy_density: strain and energy density differ in size");
  }
  if (!options.converged.empty() && options.converged.size() != strain.size()) {
    throw std::invalid_argument("fit_energy_density: converged flags and strain differ in size");
  }
  const std::vector<double>& u_all = energy_density;
  QuadraticFit fit;
  // The zero-strain point above the next one is dropped
  // (docs/original-code.md#energies-and-moduli).
  fit.first = options.drop_zero_point_above_next && u_all.size() >= 3 && strain[0] == 0.0 &&
                      u_all[1] < u_all[0]
                  ? 1
                  : 0;
  const std::vector<double> u_fit(u_all.begin() + static_cast<std::ptrdiff_t>(fit.first),
                                  u_all.end());
  const std::size_t n = u_fit.size();
  const std::size_t kept = points_before_kink(u_fit);
  // Fewer than 3 points before the kink cannot determine a and c with any redundancy; the
  // header's rule then fits the whole curve.
  if (kept < n && kept >= kMinFitPoints) {
    fit.points = kept;
    fit.split = true;
  } else {
    fit.points = n;
  }

  // Two unknowns need two distinct x^2; equal |x| (e.g. +-gamma only) leaves a undetermined.
  const double* x = strain.data() + fit.first;
  bool distinct = false;
  for (std::size_t i = 1; i < fit.points && !distinct; ++i) {
    distinct = std::abs(x[i]) != std::abs(x[0]);
  }
  if (distinct) {
    least_squares(x, u_fit.data(), fit.points, fit);
  } else {
    fit.modulus = fit.offset = fit.rms_residual = kNaN;
  }
  fit.problem = quadratic_problem(strain, u_all, options.converged, fit, distinct);
  fit.valid = fit.problem.empty();
  return fit;
}

LinearFit fit_stress_strain(const std::vector<double>& strain, const std::vector<double>& stress,
                            const std::vector<bool>& converged) {
  if (strain.size() != stress.size()) {
    throw std::invalid_argument("fit_stress_strain: strain and stress differ in size");
  }
  if (!converged.empty() && converged.size() != strain.size()) {
    throw std::invalid_argument("fit_stress_strain: converged flags and strain differ in size");
  }
  LinearFit fit;
  fit.points = strain.size();
  // Least squares through the origin: the unstrained state carries no stress.
  double se = 0.0;
  double ee = 0.0;
  std::size_t loaded = 0;
  for (std::size_t i = 0; i < strain.size(); ++i) {
    se += stress[i] * strain[i];
    ee += strain[i] * strain[i];
    if (strain[i] != 0.0) ++loaded;
  }
  fit.modulus = ee > 0.0 ? se / ee : kNaN;
  double sum_sq = 0.0;
  for (std::size_t i = 0; i < strain.size(); ++i) {
    const double r = stress[i] - fit.modulus * strain[i];
    sum_sq += r * r;
  }
  fit.rms_residual = fit.points > 0 ? std::sqrt(sum_sq / static_cast<double>(fit.points)) : kNaN;

  for (std::size_t i = 0; i < strain.size() && fit.problem.empty(); ++i) {
    if (!std::isfinite(strain[i]) || !std::isfinite(stress[i])) {
      fit.problem = fmt::format("non-finite point at stress {:.6g}", stress[i]);
    } else if (!converged.empty() && !converged[i]) {
      fit.problem = fmt::format("the step at stress {:.6g} did not converge", stress[i]);
    }
  }
  if (fit.problem.empty() && loaded < kMinFitPoints - 1) {
    fit.problem =
        fmt::format("only {} loaded point(s), at least {} needed", loaded, kMinFitPoints - 1);
  }
  if (fit.problem.empty() && !std::isfinite(fit.modulus)) fit.problem = "non-finite fit";
  if (fit.problem.empty() && !(fit.modulus > 0.0)) {
    fit.problem = fmt::format("slope {:.6g} is not positive", fit.modulus);
  }
  fit.valid = fit.problem.empty();
  return fit;
}

double mr_effect_percent(double modulus, double reference) {
  // Written so that a NaN reference also gives NaN (docs/original-code.md#energies-and-moduli: the
  // MR effect is relative to the modulus at the first field).
  if (!(reference > 0.0)) return std::numeric_limits<double>::quiet_NaN();
  return (modulus / reference - 1.0) * 100.0;
}

}  // namespace mresim::mess_analysis
