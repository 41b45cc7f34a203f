#pragma once

#include <vector>

#include "mresim/pair/pair_energy.hpp"
#include "mresim/pair/relaxation.hpp"

namespace mresim::pair {

// A field sweep along a fixed direction: 0 -> +B_max -> -B_max -> +B_max (Section 2.5.1), or,
// for critical-field maps, only 0 -> +B_max -> 0 (the loop is odd under B -> -B, m -> -m, so
// the first quadrant holds all of H_C1 and H_C2).
struct SweepOptions {
  double b_max = 1.0;        // T, a multiple of b_step
  double b_step = 0.01;      // T
  double theta_h_deg = 0.0;  // field angle from the pair axis, in the xz-plane
  bool first_quadrant_only = false;
  RelaxOptions relax;
};

// Field values of the sweep as integer multiples of the step, with the branch of each point:
// 0 the initial rise, 1 the descent, 2 the final rise.
struct SweepPoint {
  int step_index = 0;  // field = step_index * b_step
  int branch = 0;
};
std::vector<SweepPoint> sweep_points(const SweepOptions& options);

// One relaxed configuration.
struct PairState {
  double field = 0.0;  // T, signed value of B = mu0 H along the field direction
  int branch = 0;
  Eigen::Vector3d separation;  // d = r1 - r2, m
  PairMagnetization magnetization;
  EnergyBreakdown energy;
  int iterations = 0;
  bool converged = false;
  double position_error = 0.0;  // m, RelaxResult::position_error

  double distance() const { return separation.norm(); }
  double rotation_deg() const;  // angle of d from the x-axis in the xz-plane (Fig. 2.1b)
  double magnetization_along(const Eigen::Vector3d& direction) const;  // M/Ms of the pair
};

// Relaxes at field b (T) along `direction`, starting from `start` (metres).
PairState relax_at_field(const PairSystem& system, double b, const Eigen::Vector3d& direction,
                         const Eigen::Vector3d& start, const RelaxOptions& options);

// The zero-field configuration d0 = S0 x.
Eigen::Vector3d rest_configuration(const PairSystem& system);

struct HysteresisLoop {
  SweepOptions options;
  std::vector<PairState> states;  // in sweep order, each relaxed from the previous one
};

HysteresisLoop run_hysteresis(const PairSystem& system, const SweepOptions& options);

}  // namespace mresim::pair
