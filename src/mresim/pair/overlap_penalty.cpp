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
  return v;
}

// WCA of Section 2.4 (and eq. 4.79); derivative as eq. 4.80 with its misprint corrected
// (second term 6 r_min^6 / S^7).
PenaltyValue wca_penalty(const OverlapPenalty& p, double s) {
  PenaltyValue v;
  if (s > p.r_cut) return v;
  auto lj = [&](double r) {
    const double q6 = std::pow(p.r_min / r, 6);
    return q6 * q6 - q6;
  };
  const double q6 = std::pow(p.r_min / s, 6);
  v.energy = 4.0 * p.e_max * (q6 * q6 - q6 - lj(p.r_cut));
  v.derivative = 4.0 * p.e_max * (-12.0 * q6 * q6 + 6.0 * q6) / s;
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
