#pragma once

// The modulus of the branch after a kink (Section 4.3.2, Figs. 4.25-4.26): where clustering cuts
// the energy-density curve u(x) of one field (the split rule of modulus_fit.hpp), the points from
// the kink point to the end of the curve are a second equilibrium branch, the clustered state
// (Fig. 4.26 shows "two curves" for R_helix = 3.5 um at 100 mT; Fig. 4.25 lists that helix twice,
// once per branch). Its modulus is the curvature of
//
//     u(x) = a x^2 / 2 + b x + c,   a = d^2u/dx^2 = the second modulus,
//
// fitted by least squares over those points. The first branch is fitted with b = 0 because its
// minimum is the zero-strain state; the second branch starts at the kink strain x_k > 0 and the
// clustered state is generally not at its own minimum there (a stress remains), so b is free: a
// fit without it would take the slope of the branch for curvature. (The original fitted the
// second subset with u = a x^2/2 + c, docs/original-code.md#energies-and-moduli; with b = 0 the
// modulus of a branch u = a (x - x0)^2/2 + c0 with x0 != 0 is biased, which this form avoids.)
//
// Rules (SecondFit::valid, the first failed one in `problem`):
//   - the first fit was cut at a kink (QuadraticFit::split); otherwise no second fit,
//   - at least kSecondFitMinPoints (3) points lie from the kink point to the end; fewer leave the
//     three coefficients undetermined (the numbers are NaN),
//   - at least kSecondFitValidPoints (4) points: three points determine a, b, c exactly and carry
//     no check of the parabola (the same reason the first fit needs 3 points for its 2
//     coefficients); with exactly 3 the numbers are computed, marked not valid,
//   - every fitted point is finite and comes from a converged step,
//   - the fitted strains take at least three distinct values,
//   - a is positive and a, b, c are finite.
// Further kinks inside the second branch are not cut: it runs to the end of the curve.

#include <cstddef>
#include <string>
#include <vector>

#include "mresim/mess/analysis/modulus_fit.hpp"

namespace mresim::mess_analysis {

inline constexpr std::size_t kSecondFitMinPoints = 3;    // the coefficients are determined
inline constexpr std::size_t kSecondFitValidPoints = 4;  // the fit is a result

struct SecondFit {
  double modulus = 0.0;       // a, Pa (J/m^3 per strain^2); NaN where undetermined
  double slope = 0.0;         // b, J/m^3 per strain
  double offset = 0.0;        // c, J/m^3 (u extrapolated to zero strain)
  double rms_residual = 0.0;  // J/m^3, over the fitted points
  std::size_t first = 0;      // index of the first fitted point (the kink point); 0 without one
  std::size_t points = 0;     // fitted points: first .. end of the curve; 0 without a kink
  bool valid = false;
  std::string problem;  // why not valid ("" when valid)
};

// The fit of u = a x^2/2 + b x + c over the points of (x, u) from the kink that `first_fit`
// (fit_energy_density of the same x, u, options) was cut at to the end. x, u (and
// options.converged unless empty) must have the same size (std::invalid_argument otherwise).
SecondFit fit_after_kink(const std::vector<double>& strain,
                         const std::vector<double>& energy_density, const QuadraticFit& first_fit,
                         const FitOptions& options = {});

// The fit's form, for the /analysis attribute `second_form`.
inline constexpr const char* kSecondFitForm = "energy density = a x^2/2 + b x + c, least squares";

}  // namespace mresim::mess_analysis
