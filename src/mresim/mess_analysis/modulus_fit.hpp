#pragma once

// Effective moduli of the 3D model from strain runs (Section 4.2.8; reference-notes.md
// section 18): at each applied field the energy density u (total energy / current system
// volume) against the strain x is fitted with u(x) = a x^2 / 2 + c by least squares; a is
// G_eff for shear and E_eff for tension and compression. The MR effect is
// (a(B) / a(B_0) - 1) x 100 %, B_0 the first field.
//
// Clustering makes u(x) kink (the particles snap together at some strain); the original fits
// only the first part of the curve. The split rule: the curve is cut before the first point
// whose increment u_{i+1} - u_i is smaller than the previous increment (the increments of a
// parabola through the origin grow); if fewer than 3 points remain before the cut, all points
// are fitted and `split` stays false. The rule assumes equally spaced strains (with unequal
// spacing a parabola's increments can shrink too) and compares neighbouring increments only: a
// jump up is kept, but the ordinary increment after it is smaller and cuts there. Non-finite
// values are not screened (a NaN compares false and propagates into the fit).
//
// Like the original (reference-notes.md section 18), a first point at zero strain is dropped
// when the next point lies below it (a zero-strain state that shearing relaxes further, e.g. a
// squeezed polymer gap that buckles sideways once the symmetry is broken); the split rule then
// applies to the curve from the second point on.

#include <cstddef>
#include <vector>

namespace mresim::mess_analysis {

struct QuadraticFit {
  double modulus = 0.0;       // a, Pa (J/m^3 per strain^2)
  double offset = 0.0;        // c, J/m^3
  double rms_residual = 0.0;  // J/m^3, over the fitted points
  std::size_t first = 0;      // index of the first fitted point (1: zero-strain point dropped)
  std::size_t points = 0;     // fitted points: first .. first + points - 1
  bool split = false;         // the curve was cut (kink detected)
  bool valid = false;         // at least 2 points with distinct |x|
};

// Least-squares fit of u = a x^2/2 + c over the first points of (x, u) selected by the split
// rule. x and u must have the same size (std::invalid_argument otherwise).
QuadraticFit fit_energy_density(const std::vector<double>& strain,
                                const std::vector<double>& energy_density);

// Stress runs: modulus = least-squares slope of stress against measured strain through the
// origin, sum(s e) / sum(e^2) (Pa); valid when some strain is non-zero.
struct LinearFit {
  double modulus = 0.0;
  double rms_residual = 0.0;  // Pa
  std::size_t points = 0;
  bool valid = false;
};
// strain and stress must have the same size (std::invalid_argument otherwise).
LinearFit fit_stress_strain(const std::vector<double>& strain, const std::vector<double>& stress);

// (modulus / reference - 1) x 100 %; NaN if reference is not positive.
double mr_effect_percent(double modulus, double reference);

}  // namespace mresim::mess_analysis
