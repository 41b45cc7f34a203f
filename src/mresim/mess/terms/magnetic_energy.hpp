#pragma once

// Magnetic energy terms of the 3D model (Section 4.2.4) with exact gradients with respect to
// the particle centres, at fixed magnetizations M (A/m, one column per particle; the moment
// is m = V M). Gradient columns are dE/dr_i in J/m; the force on particle i is minus column i.
//
//   Zeeman         eq. 4.70   -mu0 V sum_i M_i . H_ext
//   dipole-dipole  eq. 4.71   -(mu0/2) sum_i m_i . H_dip,i; its gradient is minus eq. 4.78
//   self-energy    eq. 4.76   (mu0 Ms V / chi0) sum_i [-|M_i| + Ms log(Ms/(Ms - |M_i|))]
//                  (consistent, the default) or eq. 4.73, the dissertation's approximation
//                  mu0 V |M_i|^2 (Ms + chi0 |H_ext|) / (2 chi0 Ms) used for its energy plots
//   WCA            eqs. 4.79-4.80 between particle centres
//
// Why the partial gradients are the forces. With the consistent self-energy (4.76), the sum
// Zeeman + dipole + self is stationary in M exactly where M obeys the FK law (eq. 4.55; see
// particle_response.hpp). So for the self-consistent M(r) the total derivative
//   dE/dr = dE/dr|_M + (dE/dM)(dM/dr) = dE/dr|_M
// (envelope theorem): the forces on the particles are the partial gradients at fixed M, i.e.
// the dipole force eq. 4.78 plus WCA (Zeeman and self-energy do not depend on the centres in a
// uniform field). The test ParticleMagneticEnergy.EnvelopeTheorem* checks this by re-solving M
// at every displaced position. With eq. 4.73 the energy is not stationary in M, so the
// reported energy is not the potential of the dipole forces; use it for comparison with the
// dissertation's energy plots only.

#include <Eigen/Core>

#include "mresim/mess/magnetization/dipole_field.hpp"
#include "mresim/mess/magnetization/magnetic_particles.hpp"

namespace mresim::magnetism {

enum class SelfEnergyForm {
  consistent,  // eq. 4.76 (+ demagnetizing energy mu0 V |M|^2 / 6 with demagnetization)
  linearized,  // eq. 4.73 (+ the same demagnetizing energy)
};

// WCA between particle centres, eq. 4.79 with the cut-off r_cut = 2^(1/6) r_min.
struct WcaParameters {
  double e_max = 0.0;  // J; 0 switches the term off
  double r_min = 0.0;  // m

  double r_cut() const;  // 2^(1/6) r_min

  // E_max = mu0 pi Ms_scale^2 R^3 / 72 (Section 4.2.4), r_min = 2R + gap (gap = 100 nm).
  // The physical profile passes the run's Ms; the seed profile passes 1.9e6 A/m, the value
  // the original code hard-codes whatever the run's Ms (docs/original-code.md#constants).
  static WcaParameters from_radius(double radius, double ms_scale, double gap = 100e-9);
};

// Everything the magnetic terms need besides the centres and M.
struct MagneticModel {
  MagneticParticles particles;
  Eigen::Vector3d applied_field = Eigen::Vector3d::Zero();  // H_ext, A/m (B_ext / mu0)
  SelfEnergyForm self_energy = SelfEnergyForm::consistent;
  bool demagnetization = false;  // as in MagnetizationOptions; adds mu0 V |M|^2 / 6
  WcaParameters wca;             // default: off

  // The default model for `particles` with WCA scaled by wca_ms (the run's Ms when <= 0).
  static MagneticModel make(const MagneticParticles& particles,
                            const Eigen::Vector3d& applied_field, double wca_ms = 0.0);
};

// Eq. 4.70. Gradient: zero (uniform field).
double zeeman_energy(const MagneticModel& model, const Eigen::Matrix3Xd& centres,
                     const Eigen::Matrix3Xd& M);
Eigen::Matrix3Xd zeeman_gradient(const MagneticModel& model, const Eigen::Matrix3Xd& centres,
                                 const Eigen::Matrix3Xd& M);

// Eq. 4.71, summed over the pairs of the free block (OpenBoundary) or of a given pair list.
double dipole_energy(const MagneticModel& model, const Eigen::Matrix3Xd& centres,
                     const Eigen::Matrix3Xd& M);
Eigen::Matrix3Xd dipole_gradient(const MagneticModel& model, const Eigen::Matrix3Xd& centres,
                                 const Eigen::Matrix3Xd& M);
double dipole_energy(const MagneticModel& model, const PairList& pairs, const Eigen::Matrix3Xd& M);
Eigen::Matrix3Xd dipole_gradient(const MagneticModel& model, const PairList& pairs,
                                 const Eigen::Matrix3Xd& M);

// Eq. 4.76 or 4.73 (model.self_energy). +infinity (4.76) if some |M_i| >= Ms. Gradient with
// respect to the centres at fixed M: zero.
double self_energy(const MagneticModel& model, const Eigen::Matrix3Xd& centres,
                   const Eigen::Matrix3Xd& M);
Eigen::Matrix3Xd self_energy_gradient(const MagneticModel& model, const Eigen::Matrix3Xd& centres,
                                      const Eigen::Matrix3Xd& M);

// Eqs. 4.79-4.80 (second term of 4.80 corrected to 6 r_min^6 / S^7), independent of M.
double wca_energy(const MagneticModel& model, const Eigen::Matrix3Xd& centres);
Eigen::Matrix3Xd wca_gradient(const MagneticModel& model, const Eigen::Matrix3Xd& centres);
double wca_energy(const MagneticModel& model, const PairList& pairs);
Eigen::Matrix3Xd wca_gradient(const MagneticModel& model, const PairList& pairs,
                              int particle_count);

// WCA of one pair at centre distance S: energy (J) and dE/dS (J/m). Evaluated as
// E = E_max w^2 with w = (r_cut/S)^6 - 1 = (r_cut - S) P(S) / S^6 (P a product of positive
// sums), which stays accurate to rounding right up to the cut-off, where the textbook
// q^12 - q^6 + 1/4 cancels to noise (compare src/mresim/pair/overlap_penalty.cpp).
struct WcaValue {
  double energy = 0.0;
  double derivative = 0.0;
};
WcaValue wca_pair(const WcaParameters& wca, double separation);
// d^2E/dS^2 of one pair, 12 E_max (1 + w)(6 + 13 w) / S^2 (0 at and beyond the cut-off).
double wca_pair_curvature(const WcaParameters& wca, double separation);

struct MagneticEnergyBreakdown {
  double zeeman = 0.0;
  double dipole = 0.0;
  double self = 0.0;
  double wca = 0.0;
  double total() const { return zeeman + dipole + self + wca; }
};

// All terms for the free block.
MagneticEnergyBreakdown magnetic_energies(const MagneticModel& model,
                                          const Eigen::Matrix3Xd& centres,
                                          const Eigen::Matrix3Xd& M);

// Sum of the four gradients at fixed M (dipole + WCA). With the self-consistent M and the
// consistent self-energy this is the exact gradient of magnetic_energies().total() as a
// function of the centres alone.
Eigen::Matrix3Xd magnetic_gradient(const MagneticModel& model, const Eigen::Matrix3Xd& centres,
                                   const Eigen::Matrix3Xd& M);

}  // namespace mresim::magnetism
