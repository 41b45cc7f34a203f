#include "mresim/pair/overlap_penalty.hpp"

#include <cmath>

namespace mresim::pair {
namespace {

// E_max (tanh(x) + 1)/2 = E_max / (1 + exp(-2x)): the logistic form keeps full relative
// precision far from contact, where tanh(x) + 1 would cancel to zero.
PenaltyValue tanh_penalty(const OverlapPenalty& p, double radius, double s) {
  const double u = 1.0 / s - 0.5 / radius;
  const double x = u / p.delta;
  PenaltyValue v;
  if (x < -350.0) return v;  // below double precision relative to anything else in eq. 2.3
  v.energy = p.e_max / (1.0 + std::exp(-2.0 * x));
  const double sech = 2.0 / (std::exp(x) + std::exp(-x));
  // dE/dS = E_max/2 sech^2(x) * (1/delta) * du/dS, du/dS = -1/S^2.
  v.derivative = -0.5 * p.e_max * sech * sech / (p.delta * s * s);
  // d/dS of E_max/2 sech^2(x) x' with x' = -1/(delta S^2): (sech^2)' = -2 sech^2 tanh x'.
  const double x_prime = -1.0 / (p.delta * s * s);
  const double x_second = 2.0 / (p.delta * s * s * s);
  v.second_derivative =
      0.5 * p.e_max * sech * sech * (-2.0 * std::tanh(x) * x_prime * x_prime + x_second);
  return v;
}

// WCA of Section 2.4 (and eq. 4.79); derivative as eq. 4.80 with its misprint corrected
// (second term 6 r_min^6 / S^7).
PenaltyValue wca_penalty(const OverlapPenalty& p, double s) {
  PenaltyValue v;
  if (s > p.r_cut) return v;
  const double q6 = std::pow(p.r_min / s, 6);
  // The default cut-off 2^(1/6) r_min is the minimum of the Lennard-Jones form, so the penalty
  // is purely repulsive; rounded, r_cut lands an ulp or so past that minimum, and there the
  // sliver of attractive force (E_max is ~1e8 mu0 Ms^2 V, so ~1e-6 of the scaled force unit)
  // would hold a soft-spring pair at the cut-off. For that cut-off the penalty is zero
  // wherever (r_min/S)^6 <= 1/2 (exact: 2 q6 - 1 has no rounding error there).
  const double lj_minimum = std::pow(2.0, 1.0 / 6.0) * p.r_min;
  if (std::abs(p.r_cut - lj_minimum) <= 1e-12 * lj_minimum && 2.0 * q6 <= 1.0) return v;
  // Factored forms: E_max is ~1e8 times the magnetic energy scale, so the textbook sum
  // q^12 - q^6 + 1/4 would lose all significant digits to cancellation near the cut-off.
  // (q12 - q6) - (qc12 - qc6) = (q6 - qc6)(q6 + qc6 - 1).
  const double qc6 = std::pow(p.r_min / p.r_cut, 6);
  v.energy = 4.0 * p.e_max * (q6 - qc6) * (q6 + qc6 - 1.0);
  v.derivative = -24.0 * p.e_max * q6 * (2.0 * q6 - 1.0) / s;
  v.second_derivative = 4.0 * p.e_max * (156.0 * q6 * q6 - 42.0 * q6) / (s * s);
  return v;
}

}  // namespace

PenaltyValue overlap_penalty(const OverlapPenalty& penalty, double radius, double separation) {
  return penalty.kind == PenaltyKind::tanh ? tanh_penalty(penalty, radius, separation)
                                           : wca_penalty(penalty, separation);
}

double contact_separation(const OverlapPenalty& penalty, double radius) {
  return penalty.kind == PenaltyKind::tanh ? 2.0 * radius : penalty.r_cut;
}

}  // namespace mresim::pair
