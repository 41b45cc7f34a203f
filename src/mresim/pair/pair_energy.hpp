#pragma once

#include <Eigen/Core>

#include "mresim/pair/pair_magnetization.hpp"
#include "mresim/pair/pair_system.hpp"

namespace mresim::pair {

// Terms of eq. 2.3 / 2.4 in joules, for one configuration with its relaxed magnetization.
struct EnergyBreakdown {
  double zeeman = 0.0;
  double dipole = 0.0;
  double self = 0.0;
  double spring = 0.0;   // k12 (or k) spring between the spheres
  double anchor = 0.0;   // k0 springs to the zero-field positions (three-spring model)
  double penalty = 0.0;  // overlap penalty
  double total() const { return zeeman + dipole + self + spring + anchor + penalty; }
};

// Energy of the pair as a function of the separation vector d = r1 - r2, at a fixed applied
// field, with the magnetization relaxed at every d (Section 2.4: "at each step of the energy
// minimization procedure, the magnetization was determined"). Internally lengths are in units
// of R and energies in units of mu0 Ms^2 V, which keeps the minimiser well conditioned.
//
// The three-spring model's anchor springs act on both centres; with the centre of mass c and
// d, (k0/2)(|r1-r1,0|^2 + |r2-r2,0|^2) = k0 |c - c0|^2 + (k0/4)|d - d0|^2, so c stays at c0
// and only d needs relaxing. The zero-field separation vector is d0 = S0 x.
class PairEnergy {
 public:
  PairEnergy(const PairSystem& system, const Eigen::Vector3d& applied_field_tesla);

  // Scaled interface used by the relaxation (d in units of R, energy in mu0 Ms^2 V).
  double scaled_energy(const Eigen::Vector3d& d) const;
  // Exact gradient dE/dd (scaled); the magnetization is the constrained minimiser, so its
  // variation does not contribute (envelope theorem).
  Eigen::Vector3d scaled_gradient(const Eigen::Vector3d& d) const;
  // Hessian (scaled): the springs and the penalty, which depend only on |d| and can be
  // extremely stiff, analytically; the smooth magnetic part by central differences of its
  // exact gradient. Splitting them keeps the soft directions (rotation of a clustered pair)
  // resolved next to a wall 1e13 times stiffer.
  Eigen::Matrix3d scaled_hessian(const Eigen::Vector3d& d) const;
  // Both at once, with one magnetization solve (the relaxation's hot path).
  double scaled_energy_and_gradient(const Eigen::Vector3d& d, Eigen::Vector3d& gradient) const;

  EnergyBreakdown breakdown(const Eigen::Vector3d& d) const;  // joules
  PairMagnetization magnetization(const Eigen::Vector3d& d) const;

  double length_scale() const { return radius_; }
  double energy_scale() const { return energy_scale_; }

 private:
  EnergyBreakdown scaled_terms(const Eigen::Vector3d& d, const PairMagnetization& mag) const;
  Eigen::Vector3d scaled_gradient_at(const Eigen::Vector3d& d, const Eigen::Vector3d& m) const;
  Eigen::Vector3d magnetic_gradient(const Eigen::Vector3d& d, const Eigen::Vector3d& m) const;

  PairSystem system_;
  Eigen::Vector3d reduced_field_;
  double radius_;
  double energy_scale_;
  double k12_;  // scaled spring constants k R^2 / (mu0 Ms^2 V)
  double k0_;
  double rest_;  // S0 / R
};

}  // namespace mresim::pair
