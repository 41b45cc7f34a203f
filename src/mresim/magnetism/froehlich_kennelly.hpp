#pragma once

// Isotropic, anhysteretic magnetization laws of dissertation Section 1.3.3:
//   eq. 1.4  M = chi H, here with |M| clipped to Ms ("linear response with clipped maximum
//            magnitude of Ms"), used for the dipole-spring models of Chapters 2 and 3;
//   eq. 1.5  Froehlich-Kennelly law M = Ms chi0 H / (Ms + chi0 |H|), used in Chapter 4.
// In both, M is collinear with the total field H at the particle centre. H and M in A/m.
// The Jacobians dM/dH are analytic and meant for Newton solves of the self-consistent
// magnetization of interacting particles.

#include <Eigen/Core>

#include "mresim/magnetism/magnetization_curve.hpp"

namespace mresim::magnetism {

// Eq. 1.5, vector form. Requires chi0 >= 0 and Ms > 0 (finite), else std::invalid_argument.
Eigen::Vector3d froehlich_kennelly(const Eigen::Vector3d& H, double chi0, double Ms);

// Eq. 1.5, scalar (collinear) form: M(H) = Ms chi0 H / (Ms + chi0 |H|), odd in H.
double froehlich_kennelly(double H, double chi0, double Ms);

// Differential susceptibility of eq. 1.5, dM/dH = Ms^2 chi0 / (Ms + chi0 |H|)^2.
double froehlich_kennelly_derivative(double H, double chi0, double Ms);

// Jacobian dM_i/dH_j of eq. 1.5. With h = |H|, u = H / h and f = Ms chi0 / (Ms + chi0 h):
//   dM/dH = f [ I - chi0 h / (Ms + chi0 h) u u^T ],
// i.e. the secant susceptibility f transverse to H and the differential susceptibility
// f Ms / (Ms + chi0 h) along H. At H = 0 it is chi0 I (the limit of the formula).
Eigen::Matrix3d froehlich_kennelly_jacobian(const Eigen::Vector3d& H, double chi0, double Ms);

// Eq. 1.4 with saturation: M = chi H when chi |H| <= Ms, else M = Ms H / |H|.
// Requires chi >= 0 and Ms > 0 (finite), else std::invalid_argument.
Eigen::Vector3d linear_saturable(const Eigen::Vector3d& H, double chi, double Ms);

// Scalar form of eq. 1.4 with saturation: M = clamp(chi H, -Ms, Ms).
double linear_saturable(double H, double chi, double Ms);

// Jacobian of linear_saturable: chi I below saturation; (Ms / |H|) (I - u u^T) above it
// (only the direction of H can change M there). At the kink chi |H| = Ms the unsaturated
// branch chi I is returned.
Eigen::Matrix3d linear_saturable_jacobian(const Eigen::Vector3d& H, double chi, double Ms);

// M/Ms of eq. 1.5 along the major-loop sweep 0 -> +b_max -> -b_max -> +b_max (see
// major_loop_sweep), for an applied field B = mu0 H (no demagnetizing field), as in Fig. 1.6
// (chi0 = 70, Ms = 1.6e6 A/m there). Being anhysteretic, all branches coincide.
MagnetizationCurve froehlich_kennelly_loop(double chi0, double Ms, double b_max, double b_step);

}  // namespace mresim::magnetism
