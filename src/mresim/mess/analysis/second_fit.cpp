#include "mresim/mess/analysis/second_fit.hpp"

#include <fmt/format.h>

#include <Eigen/Core>
#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace mresim::mess_analysis {

namespace {

constexpr double kSecondFitNaN = std::numeric_limits<double>::quiet_NaN();

SecondFit undetermined(std::size_t first, std::size_t points, std::string problem) {
  return {kSecondFitNaN, kSecondFitNaN, kSecondFitNaN, kSecondFitNaN,
          first,         points,        false,         std::move(problem)};
}

std::size_t distinct_values(std::vector<double> x) {
  std::sort(x.begin(), x.end());
  return static_cast<std::size_t>(std::unique(x.begin(), x.end()) - x.begin());
}

// Least squares of u = a x^2/2 + b x + c. The strains are centred on their mean m first
// (u = a t^2/2 + b' t + c', t = x - m), which keeps the three columns well apart for strains
// far from zero (x = 0.03 ... 0.1: x^2/2, x and 1 are nearly collinear); then
// b = b' - a m and c = c' - b' m + a m^2/2.
void least_squares_with_slope(const std::vector<double>& x, const std::vector<double>& u,
                              SecondFit& fit) {
  const auto n = static_cast<Eigen::Index>(x.size());
  double m = 0.0;
  for (const double xi : x) m += xi;
  m /= static_cast<double>(x.size());
  Eigen::MatrixX3d design(n, 3);
  Eigen::VectorXd rhs(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const double t = x[static_cast<std::size_t>(i)] - m;
    design(i, 0) = 0.5 * t * t;
    design(i, 1) = t;
    design(i, 2) = 1.0;
    rhs(i) = u[static_cast<std::size_t>(i)];
  }
  const Eigen::Vector3d k = design.colPivHouseholderQr().solve(rhs);
  fit.modulus = k(0);
  fit.slope = k(1) - k(0) * m;
  fit.offset = k(2) - k(1) * m + 0.5 * k(0) * m * m;
  fit.rms_residual = std::sqrt((design * k - rhs).squaredNorm() / static_cast<double>(n));
}

// The first rule of second_fit.hpp after the point count that the fit breaks, or "".
std::string second_fit_problem(const std::vector<double>& x, const std::vector<double>& u,
                               const std::vector<bool>& converged, std::size_t first,
                               const SecondFit& fit) {
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (!std::isfinite(x[i]) || !std::isfinite(u[i])) {
      return fmt::format("non-finite point at strain {:.6g}", x[i]);
    }
  }
  if (fit.points < kSecondFitValidPoints) {
    return fmt::format(
        "only {} point(s) after the kink: they determine a, b, c exactly with no check, at least "
        "{} needed",
        fit.points, kSecondFitValidPoints);
  }
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (!converged.empty() && !converged[first + i]) {
      return fmt::format("the step at strain {:.6g} did not converge", x[i]);
    }
  }
  if (!std::isfinite(fit.modulus) || !std::isfinite(fit.slope) || !std::isfinite(fit.offset) ||
      !std::isfinite(fit.rms_residual)) {
    return "non-finite fit";
  }
  if (!(fit.modulus > 0.0)) {
    return fmt::format("curvature {:.6g} after the kink is not positive", fit.modulus);
  }
  return {};
}

}  // namespace

SecondFit fit_after_kink(const std::vector<double>& strain,
                         const std::vector<double>& energy_density, const QuadraticFit& first_fit,
                         const FitOptions& options) {
  if (strain.size() != energy_density.size()) {
    throw std::invalid_argument("fit_after_kink: strain and energy density differ in size");
  }
  if (!options.converged.empty() && options.converged.size() != strain.size()) {
    throw std::invalid_argument("fit_after_kink: converged flags and strain differ in size");
  }
  if (!first_fit.split) return undetermined(0, 0, "no kink");
  const std::size_t first = first_fit.first + first_fit.points;
  if (first >= strain.size()) {
    throw std::invalid_argument("fit_after_kink: the first fit ends past the curve");
  }
  const std::size_t points = strain.size() - first;
  const auto begin = static_cast<std::ptrdiff_t>(first);
  const std::vector<double> x(strain.begin() + begin, strain.end());
  const std::vector<double> u(energy_density.begin() + begin, energy_density.end());
  if (points < kSecondFitMinPoints) {
    return undetermined(first, points,
                        fmt::format("only {} point(s) after the kink, at least {} needed", points,
                                    kSecondFitMinPoints));
  }
  bool finite = true;
  for (std::size_t i = 0; i < points; ++i) {
    finite = finite && std::isfinite(x[i]) && std::isfinite(u[i]);
  }
  if (finite && distinct_values(x) < 3) {
    return undetermined(first, points, "the strains after the kink take fewer than 3 values");
  }
  SecondFit fit{kSecondFitNaN, kSecondFitNaN, kSecondFitNaN, kSecondFitNaN,
                first,         points,        false,         {}};
  if (finite) least_squares_with_slope(x, u, fit);
  fit.problem = second_fit_problem(x, u, options.converged, first, fit);
  fit.valid = fit.problem.empty();
  return fit;
}

}  // namespace mresim::mess_analysis
