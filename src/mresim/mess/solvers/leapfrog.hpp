#pragma once

// The dissertation's damped leapfrog relaxation (Sections 4.2.4-4.2.6;
// docs/original-code.md#time-integration), kept as the reference integrator against which the
// minimisers are measured (docs/architecture.md#principles). It integrates Newton's equations with
// a drag force (eqs. 4.81-4.84) until the lattice stops moving.
//
// Scaled units (Section 4.2.6, eqs. 4.94-4.95): x_c = l_e, m_c = rho_polymer l_e^3,
// k_eff = 2 k_e + 8 k_f/sqrt(2) + 4 k_c (the polymer's bulk constants), t_c = 2 pi sqrt(m_c/k_eff);
// positions in l_e, time in t_c, accelerations a_i = beta_i F_i with beta_i = t_c^2/(l_e m_i),
// drag a_i -= drag v_i (drag = 1: in SI a damping rate 1/t_c on every node, i.e. a
// mass-proportional drag -m_i v_i/t_c; the dissertation's eq. 4.81 writes one eta for all).
//
// Integration (eqs. 4.88-4.89, docs/original-code.md#time-integration): start at rest, v += (dt/2)
// a(x0) (the Euler kick-start); then per step x += dt v, a = a(x, v) with the lagged half-step v,
// v += dt a. The magnetization is re-solved per the system's MagnetizationUpdate (the original:
// every step, with history). Acceleration assembly, in the original's order: forces (all
// terms; particle forces spread evenly over the particle's nodes) times beta_i, minus drag v,
// held coordinates set to 0, rigid-group nodes replaced by the group's acceleration.
//
// Convergence (docs/original-code.md#convergence), checked at the end of each integration round of
// steps_per_round steps: the mean |component| of the accelerations and of the velocities over
// all coordinates of polymer nodes that are not held are both below the tolerance (and also
// over the rigid-group and loaded nodes separately, when there are any). The relaxation stops
// when this criterion holds in `consecutive_rounds` (2) consecutive rounds, at least
// `min_rounds` (4) rounds have run, and the solution-difference norm |x(t) - x(t - 200 steps)|
// (sampled every 200 steps) did not grow between its last two samples. Tolerance by default the
// original's: the mean over all initial node coordinates of ulp_float32(coordinate)/dt (scaled).
// Max rounds reached: status max_rounds; with 1-7 particles one more round is granted, up to
// twice the maximum, while the first particle's mean nodal velocity has a component above the
// tolerance. Non-finite accelerations: status not_finite.
//
// Differences from the original: double precision throughout (the original integrates in
// float32); the rigid-group rule is selectable (the original averages the accelerations of the
// group's nodes, whose equilibrium is sum F_i/m_i = 0 rather than sum F_i = 0 when the group's
// masses differ, e.g. a face with its edge and corner nodes).

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "mresim/mess/solvers/relaxation_observer.hpp"
#include "mresim/mess/system/system_energy.hpp"

namespace mresim::mess {

struct LeapfrogScales {
  double length = 0.0;  // x_c = l_e, m
  double mass = 0.0;    // m_c = rho_polymer l_e^3, kg
  double k_eff = 0.0;   // eq. 4.95, N/m
  double time = 0.0;    // t_c, eq. 4.94, s
  double beta = 0.0;    // t_c^2 / l_e; beta_i = beta / m_i

  static LeapfrogScales of(const lattice::Lattice& lattice);
};

enum class RigidGroupRule {
  mean_acceleration,  // the original: every node gets the mean of the group's accelerations
  total_force,        // total force / total mass (equilibrium: net force zero)
};

struct LeapfrogOptions {
  double time_step = 5e-3;  // t_c (4e-3 in the helix runs; n_d <= 2 needs less than 5e-3)
  double drag = 1.0;        // scaled
  int steps_per_round = 5000;
  int max_rounds = 40;
  int min_rounds = 4;
  int consecutive_rounds = 2;
  int difference_interval = 200;  // steps between samples of |x(t) - x(t - interval)|
  double tolerance = 0.0;         // scaled (l_e/t_c, l_e/t_c^2); <= 0: the original's rule
  // docs/original-code.md#convergence: at |B| ~ 0 with boundary value 0 the first round meeting the
  // criterion ends the step. The caller (a protocol) decides when that applies.
  bool first_round_may_end = false;
  bool extend_for_moving_particles = true;
  RigidGroupRule rigid_group_rule = RigidGroupRule::total_force;  // the profile decides
  // Told the time steps and the mean |a| every difference_interval steps (progress reports);
  // changes nothing.
  RelaxationObserver observer;

  void validate() const;  // throws std::invalid_argument naming the option
};

enum class LeapfrogStatus { converged, max_rounds, not_finite };
std::string to_string(LeapfrogStatus status);

struct LeapfrogRound {
  double mean_abs_acceleration = 0.0;  // scaled, main mask
  double mean_abs_velocity = 0.0;
  double boundary_mean_abs_acceleration = 0.0;  // rigid-group and loaded nodes (0 if none)
  double boundary_mean_abs_velocity = 0.0;
  double difference_norm = 0.0;  // last |x(t) - x(t - interval)|, l_e
  bool criterion_met = false;
};

struct LeapfrogResult {
  LeapfrogStatus status = LeapfrogStatus::max_rounds;
  bool converged = false;
  int rounds = 0;
  std::int64_t steps = 0;
  double tolerance = 0.0;  // scaled, as used
  LeapfrogScales scales;
  std::vector<LeapfrogRound> history;  // one entry per round
  Eigen::Matrix3Xd velocities;         // final half-step velocities, l_e/t_c
  Evaluation final;                    // energies at the end (current M)
  std::int64_t magnetization_solves = 0;
  std::int64_t unconverged_magnetization_solves = 0;
};

// The original's tolerance: mean over all coordinates of the initial (scaled) node positions
// of ulp_float32(value) / dt (about 5e-4 for 42 x 42 x 83 nodes at dt = 5e-3).
double seed_convergence_tolerance(const lattice::Lattice& lattice, double time_step);

// Relaxes system.positions() from rest (held coordinates stay where the constraints put them).
LeapfrogResult relax_leapfrog(MessSystem& system, const LeapfrogOptions& options = {});

}  // namespace mresim::mess
