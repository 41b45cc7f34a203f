#pragma once

// Response of one isotropic, anhysteretic particle to the field at its centre, in reduced
// units m = M/Ms, h = H/Ms (as the original code solves, docs/original-code.md#magnetization).
//
// Without demagnetization this is the Froehlich-Kennelly law, eq. 4.55 (= eq. 1.5):
//   m = chi h / (1 + chi |h|).
// With demagnetization the law acts on the internal field of a uniformly magnetized sphere,
//   m = FK(h - m/3),
// an extension (docs/magnetization-3d.md): a real sphere's apparent susceptibility is then
// chi/(1 + chi/3) <= 3 instead of chi = 70. Solved in closed form below.
//
// Both laws are gradients of a convex "self-energy" s(m) (in units of mu0 Ms^2 V):
//   ds/dm = h(m)  (the field that produces m),
// with s the reduced eq. 4.76, s(m) = [-|m| - log(1 - |m|)] / chi, plus |m|^2/6 with
// demagnetization (the demagnetizing energy mu0 V M^2 / 6 of a sphere, N = 1/3). This is what
// makes the self-consistent magnetization a stationary point of the magnetic energy
// (self_consistent.hpp, magnetic_energy.hpp).

#include <Eigen/Core>

namespace mresim::magnetism {

// m(h): the law above, collinear with h. chi > 0.
Eigen::Vector3d particle_response(const Eigen::Vector3d& h, double chi, bool demagnetization);

// Jacobian dm/dh = s(|h|) (I - u u^T) + m'(|h|) u u^T, u = h/|h|, s = |m|/|h| the secant and
// m' the differential susceptibility. At h = 0 it is m'(0) I (chi, or chi/(1 + chi/3)).
Eigen::Matrix3d particle_response_jacobian(const Eigen::Vector3d& h, double chi,
                                           bool demagnetization);

// Inverse law h(m) for |m| < 1: m / (chi (1 - |m|)) [+ m/3]. Infinite at |m| >= 1.
Eigen::Vector3d particle_response_inverse(const Eigen::Vector3d& m, double chi,
                                          bool demagnetization);

// dh/dm, the inverse of particle_response_jacobian at h = h(m):
//   [I + a/(1-a) m^ m^T] / (chi (1 - a)) [+ I/3],  a = |m| < 1.
// It is the per-particle block of the Hessian of the magnetic energy over m.
Eigen::Matrix3d particle_response_inverse_jacobian(const Eigen::Vector3d& m, double chi,
                                                   bool demagnetization);

// Reduced self-energy s(m) (eq. 4.76 divided by mu0 Ms^2 V, [+ |m|^2/6]); +infinity for
// |m| >= 1 (the law never reaches saturation at a finite field).
double reduced_self_energy(const Eigen::Vector3d& m, double chi, bool demagnetization);

}  // namespace mresim::magnetism
