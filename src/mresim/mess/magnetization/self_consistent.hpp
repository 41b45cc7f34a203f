#pragma once

// Self-consistent magnetization of N interacting particles (Section 4.2.3): solve
//   M_i = FK(H_ext + H_dip,i(M))   for every particle i        (eqs. 4.55-4.58)
// with FK the Froehlich-Kennelly law (optionally applied to the internal field, see
// MagnetizationOptions::demagnetization) and H_dip the point-dipole fields (eq. 4.57).
//
// Strategy (docs/magnetization-3d.md):
//  1. fixed_point: the dissertation's iteration M <- FK(H_ext + H_dip(M)), started from the
//     previous solution (history) or, without one, from FK(H_ext). It converges only where
//     the iteration map contracts. Near contact the susceptibility times the (negative)
//     dipole coupling transverse to a bond is below -1 (chi0 = 70: -70/24 at contact), so
//     each step overshoots: low-symmetry near-contact configurations oscillate for ever.
//  2. anderson: Anderson acceleration (type II, Walker & Ni 2011) of the same map. Being a
//     root finder it also converges to unstable solutions (saddles of the energy below);
//     in near-contact triples that happens more often than not. Its answer is therefore
//     accepted only where the energy Hessian is positive definite (Cholesky); otherwise it
//     is discarded and Newton starts from where Anderson started.
//  3. newton: damped Newton minimisation of the magnetic energy over M,
//       E(M) = U_self(eq. 4.76) + U_Zeeman(eq. 4.70) + U_dip-dip(eq. 4.71),
//     whose stationarity condition is exactly the FK law. Its Hessian is blockdiag of the
//     inverse FK Jacobians minus the dipole coupling; a diagonal shift makes it positive
//     definite where it is not, and a backtracking line search on E keeps every |M_i| < Ms.
//     Being a descent method it ends in a local minimum of E; a state that meets the
//     tolerance where the Hessian is not positive definite is not accepted but left along
//     the eigenvector of most negative curvature.
// Each method starts from the lowest-residual state of the previous ones, Anderson's excluded
// (the history for the first); the first that meets the tolerance returns. The fixed point
// converges only where its map contracts, and such solutions are local minima of the energy, so the
// chain returns stable states unless started exactly on an unstable one (M = 0 at zero field; see
// MagnetizationOptions::check_stability). Every method is judged by the same criterion on
// the fixed-point residual r = FK(H_ext + H_dip(M)) - M of the returned M (in units of Ms,
// per component):
//   |r_q| <= atol + rtol |m_q|  for all q   (Section 4.2.3, step 3),
// by default with atol = rtol = 1e-12 (MagnetizationTolerance::tight), the original code's
// 1e-3 and 5e-3 on request (MagnetizationTolerance::original).
// A result that misses it has converged == false; nothing unconverged is returned silently.

#include <Eigen/Core>
#include <limits>
#include <string>
#include <vector>

#include "mresim/mess/magnetization/dipole_field.hpp"
#include "mresim/mess/magnetization/magnetic_particles.hpp"

namespace mresim::magnetism {

enum class MagnetizationMethod { fixed_point, anderson, newton };

std::string to_string(MagnetizationMethod method);

// Named tolerances of the convergence test |r_q| <= atol + rtol |m_q| (docs/magnetization-3d.md).
enum class MagnetizationTolerance {
  // atol = rtol = 1e-12 (the default): M is the self-consistent solution to near machine
  // precision at every accepted state. The residual floor of the chain is about 2e-16 (measured
  // on 24,000 random clusters of 2-60 particles, touching ones included), so 1e-12 is reached
  // every time; more fixed-point iterations per solve than the loose band (13 against 1 on a
  // two-particle loop), each O(N^2), the same wall time beside the lattice.
  tight,
  // atol = 1e-3, rtol = 5e-3: the original code's (and the dissertation's) loose band, only to
  // reproduce its behaviour. A solve whose start is already inside it returns the start
  // unchanged, so M lags the positions by up to the band (a few 1e-3 Ms, nm in separations).
  original,
};

std::string to_string(MagnetizationTolerance tolerance);

struct MagnetizationOptions {
  static constexpr double kTightAtol = 1e-12;  // Ms
  static constexpr double kTightRtol = 1e-12;
  static constexpr double kOriginalAtol = 1e-3;  // Ms
  static constexpr double kOriginalRtol = 5e-3;

  // Convergence on M/Ms, per component (Section 4.2.3, step 3); tight by default.
  double atol = kTightAtol;
  double rtol = kTightRtol;
  // Apply FK to the internal field H_local - M/3 of a uniformly magnetized sphere (off by
  // default: the dissertation's law, needed to reproduce its figures).
  bool demagnetization = false;
  // Methods tried in order (the fallback chain); each gets its own iteration budget.
  std::vector<MagnetizationMethod> methods = {
      MagnetizationMethod::fixed_point, MagnetizationMethod::anderson, MagnetizationMethod::newton};
  int max_fixed_point_iterations = 60;  // the original's limit inside the dynamics
  // The fixed point gives up early when its residual has not dropped below stall_factor times
  // its value stall_window iterations before (0 disables).
  int stall_window = 15;
  double stall_factor = 0.9;
  int max_anderson_iterations = 100;
  int anderson_depth = 5;
  int max_newton_iterations = 100;
  // Also decide whether the returned M is a local minimum of the energy over M (the dense
  // Hessian's smallest eigenvalue; O(N^3)). M = 0 at zero field is always a solution, but an
  // unstable one for touching particles with chi = 70 (zero-field instability).
  bool check_stability = false;

  // Sets atol and rtol to the named tolerance's values.
  void set_tolerance(MagnetizationTolerance tolerance);
  // The options with the original code's loose tolerance (everything else at its default).
  [[nodiscard]] static MagnetizationOptions original();

  void validate() const;  // throws std::invalid_argument naming the option
};

enum class Stability { not_checked, stable, unstable };

struct MagnetizationAttempt {
  MagnetizationMethod method = MagnetizationMethod::fixed_point;
  int iterations = 0;  // residual (field) evaluations of this method
  double scaled_residual = std::numeric_limits<double>::infinity();  // best reached
  bool converged = false;
  // Anderson met the tolerance at a saddle of the energy over M (not a local minimum); its
  // answer was discarded and the next method started from where Anderson did.
  bool rejected_unstable = false;
};

struct MagnetizationResult {
  Eigen::Matrix3Xd M;  // A/m, one column per particle
  bool converged = false;
  MagnetizationMethod method = MagnetizationMethod::fixed_point;  // produced M
  int iterations = 0;                                             // of that method
  int total_iterations = 0;                                       // of every method tried
  // Of the returned M: residual = max_q |r_q| (units of Ms); scaled_residual = max_q
  // |r_q| / (atol + rtol |m_q|), <= 1 exactly when converged.
  double residual = 0.0;
  double scaled_residual = 0.0;
  std::vector<MagnetizationAttempt> attempts;  // every method tried, in order
  Stability stability = Stability::not_checked;
  // Smallest eigenvalue of the energy Hessian over M/Ms in units of mu0 Ms^2 V (NaN unless
  // checked); positive for a stable state.
  double min_hessian_eigenvalue = std::numeric_limits<double>::quiet_NaN();
};

// Solve for the magnetizations (A/m) of particles at `centres` (m, one column each) in the
// uniform applied field H_ext (A/m). `initial_guess` (A/m) is the history, normally the
// previous solution; an empty matrix (0 columns) means "none": start from FK(H_ext).
[[nodiscard]] MagnetizationResult solve_magnetization(const Eigen::Matrix3Xd& centres,
                                                      const MagneticParticles& particles,
                                                      const Eigen::Vector3d& applied_field,
                                                      const Eigen::Matrix3Xd& initial_guess,
                                                      const MagnetizationOptions& options = {});

// The same for a prebuilt coupling (another displacement policy, e.g. periodic images).
// The coupling must have been built with particles.volume().
[[nodiscard]] MagnetizationResult solve_magnetization(const DipoleCoupling& coupling,
                                                      const MagneticParticles& particles,
                                                      const Eigen::Vector3d& applied_field,
                                                      const Eigen::Matrix3Xd& initial_guess,
                                                      const MagnetizationOptions& options = {});

// Fixed-point residual r = FK(H_ext + H_dip(M)) - M in A/m (the law with or without
// demagnetization), e.g. to check a saved state.
Eigen::Matrix3Xd magnetization_residual(const DipoleCoupling& coupling,
                                        const MagneticParticles& particles,
                                        const Eigen::Vector3d& applied_field,
                                        const Eigen::Matrix3Xd& M, bool demagnetization);

}  // namespace mresim::magnetism
