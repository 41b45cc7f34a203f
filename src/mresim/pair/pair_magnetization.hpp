#pragma once

#include <Eigen/Core>

namespace mresim::pair {

// Magnetization of two identical spheres in a uniform reduced field h = H/Ms (eq. 2.1-2.2),
// with the separation vector d = r1 - r2 in units of the radius R.
//
// Eqs. 2.5-2.7 form the linear system (I - chi D) m = chi h for both moments; with the
// saturation limit |m_i| <= 1 we take m_i as the minimiser, over |m_i| <= 1, of the magnetic
// part of eq. 2.3. Its stationarity condition is eq. 2.1 below saturation and m_i parallel to
// h_eff at saturation (the saturable linear law), and it makes the relaxation forces the exact
// gradient of the reported energy (envelope theorem). The problem is convex and symmetric under
// exchange of the spheres, so m1 = m2 and only one moment is returned.
struct PairMagnetization {
  Eigen::Vector3d m = Eigen::Vector3d::Zero();  // m1 = m2, in units of Ms
  bool saturated = false;
};

// Dipole coupling D = (R^3/3)(3 n n^T - I)/S^3 of eq. 2.2 in units where R = 1: h_dip = D m.
// (Eq. 2.6 as printed drops the 1/3 of V/(4 pi) = R^3/3; eq. 2.2 is the consistent form.)
Eigen::Matrix3d dipole_coupling(const Eigen::Vector3d& d_over_r);

PairMagnetization solve_pair_magnetization(const Eigen::Vector3d& d_over_r,
                                           const Eigen::Vector3d& reduced_field,
                                           double susceptibility);

}  // namespace mresim::pair
