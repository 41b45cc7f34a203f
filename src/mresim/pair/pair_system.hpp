#pragma once

#include <Eigen/Core>

#include "mresim/core/constants.hpp"

// The two-dipole spring models of Chapters 2-3: two identical magnetizable spheres joined by
// one spring (single-spring model, Fig. 2.1a) or by one spring plus a spring from each sphere to
// its zero-field position (three-spring model, Fig. 2.1b).
namespace mresim::pair {

// Material of the spheres (Section 2.4 defaults: carbonyl iron, R = 1.5 um).
struct SphereMaterial {
  double radius = 1.5e-6;                   // m
  double saturation_magnetization = 1.4e6;  // A/m
  double susceptibility = 2.0;              // chi of eq. 2.1 (linear, saturable)

  double volume() const;  // V = 4/3 pi R^3
  // mu0 Ms^2 V: the prefactor of every magnetic term of eq. 2.3, used as the internal energy unit.
  double magnetic_energy_scale() const;
};

enum class SpringModel { single, three };

// Spring constants in N/m. The single-spring model uses only k12 (= k of eq. 2.3);
// the three-spring model adds k0 (eq. 2.4).
struct Springs {
  SpringModel model = SpringModel::single;
  double k12 = 4e-2;
  double k0 = 0.0;
  double rest_separation = 9e-6;  // S0, m
};

enum class PenaltyKind { tanh, wca };

// Overlap penalties of Section 2.4, as functions of the centre distance S.
// tanh: E = E_max (tanh(u/delta) + 1)/2, u = 1/S - 1/(2R); delta in 1/m.
// WCA:  E = 4 E_max ((r_min/S)^12 - (r_min/S)^6) + shift for S <= r_cut, 0 beyond; the shift
//       makes E continuous at r_cut (it is the text's 1/4 when r_cut = 2^(1/6) r_min).
struct OverlapPenalty {
  PenaltyKind kind = PenaltyKind::tanh;
  double e_max = 100.0;                     // J (see docs/two-dipole-model.md for why joules)
  double delta = 1e-2;                      // 1/m, tanh width in u = 1/S - 1/(2R)
  double r_min = 3e-6;                      // m, WCA
  double r_cut = 3e-6 * 1.122462048309373;  // m, WCA, 2^(1/6) r_min

  static OverlapPenalty tanh_default(double radius);
  static OverlapPenalty wca_default(double radius);
};

struct PairSystem {
  SphereMaterial material;
  Springs springs;
  OverlapPenalty penalty;
};

// Unit vector of an applied field at angle theta_H (degrees) from the pair axis x, in the
// xz-plane (Fig. 2.1b, Fig. 2.7 caption).
Eigen::Vector3d field_direction(double theta_h_degrees);

}  // namespace mresim::pair
