#pragma once

// Effective moduli of the 3D model from strain runs (Section 4.2.8;
// docs/original-code.md#energies-and-moduli): at each applied field the energy density u (total
// energy / current system volume) against the strain x is fitted with u(x) = a x^2 / 2 + c by least
// squares; a is G_eff for shear and E_eff for tension and compression. The MR effect is (a(B) /
// a(B_0) - 1) x 100 %, B_0 the first field.
//
// Clustering makes u(x) kink (the particles snap together at some strain); the original fits
// only the first part of the curve. The split rule: the curve is cut before the first point
// whose increment u_{i+1} - u_i is smaller than the previous increment (the increments of a
// parabola through the origin grow); if fewer than 3 points remain before the cut, all points
// are fitted and `split` stays false. The rule assumes equally spaced strains (with unequal
// spacing a parabola's increments can shrink too) and compares neighbouring increments only: a
// jump up is kept, but the ordinary increment after it is smaller and cuts there. A NaN
// compares false in the rule; a non-finite fitted point makes the fit invalid (below).
//
// Like the original (docs/original-code.md#energies-and-moduli), a first point at zero strain is
// dropped when the next point lies below it (a zero-strain state that shearing relaxes further,
// e.g. a squeezed polymer gap that buckles sideways once the symmetry is broken); the split rule
// then applies to the curve from the second point on. The caller enables this for shear only
// (FitOptions::drop_zero_point_above_next): for tension, compression and torsion a point below
// the zero-strain state means the energy is not symmetric about zero strain (a pre-stress, a
// torque at zero twist), which u = a x^2/2 + c cannot describe, and the fit is invalid.
//
// Validity (QuadraticFit::valid, with the first failed condition in `problem`): a fit is a
// result only when
//   - every fitted point is finite,
//   - at least kMinFitPoints (3) points are fitted (the original's rule: 2 points interpolate
//     and carry no check of the parabola),
//   - the fitted strains take at least two values of |x|,
//   - every fitted point comes from a converged step (FitOptions::converged),
//   - when the zero-strain point is fitted, no fitted point lies below it (for the symmetric
//     parabola the zero-strain state is the minimum),
//   - the curvature a is positive (the original hides fits <= 0 too) and a, c are finite.
// An invalid fit keeps the numbers it could compute (NaN when underdetermined), so that plots
// can show them marked; they are not results.

#include <cstddef>
#include <string>
#include <vector>

namespace mresim::mess_analysis {

struct QuadraticFit {
  double modulus = 0.0;       // a, Pa (J/m^3 per strain^2)
  double offset = 0.0;        // c, J/m^3
  double rms_residual = 0.0;  // J/m^3, over the fitted points
  std::size_t first = 0;      // index of the first fitted point (1: zero-strain point dropped)
  std::size_t points = 0;     // fitted points: first .. first + points - 1
  bool split = false;         // the curve was cut (kink detected)
  bool valid = false;         // every condition of the header holds
  std::string problem;        // why not valid ("" when valid), one short phrase
};

inline constexpr std::size_t kMinFitPoints = 3;

struct FitOptions {
  // Drop a zero-strain first point that lies above the next one (shear; see above).
  bool drop_zero_point_above_next = true;
  // Per point: whether its step converged; empty means all did.
  std::vector<bool> converged;
};

// Least-squares fit of u = a x^2/2 + c over the first points of (x, u) selected by the split
// rule. x, u (and options.converged unless empty) must have the same size
// (std::invalid_argument otherwise).
QuadraticFit fit_energy_density(const std::vector<double>& strain,
                                const std::vector<double>& energy_density,
                                const FitOptions& options = {});

// Stress runs: modulus = least-squares slope of stress against measured strain through the
// origin, sum(s e) / sum(e^2) (Pa). Valid when every point is finite and converged, at least
// 2 strains are non-zero (with the origin that is kMinFitPoints points on the line), and the
// slope is positive and finite.
struct LinearFit {
  double modulus = 0.0;
  double rms_residual = 0.0;  // Pa
  std::size_t points = 0;
  bool valid = false;
  std::string problem;  // why not valid ("" when valid)
};
// strain, stress (and converged unless empty) must have the same size (std::invalid_argument
// otherwise).
LinearFit fit_stress_strain(const std::vector<double>& strain, const std::vector<double>& stress,
                            const std::vector<bool>& converged = {});

// (modulus / reference - 1) x 100 %; NaN if reference is not positive.
double mr_effect_percent(double modulus, double reference);

}  // namespace mresim::mess_analysis
