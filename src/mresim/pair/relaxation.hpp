#pragma once

#include <Eigen/Core>

#include "mresim/pair/pair_energy.hpp"

namespace mresim::pair {

// Newton (default, fast) or the nonlinear conjugate gradients the dissertation used
// (Section 2.4), kept as a reference to measure against (bench/pair_bench.cpp).
enum class RelaxMethod { newton, conjugate_gradient };

struct RelaxOptions {
  RelaxMethod method = RelaxMethod::newton;
  double gradient_tolerance = 1e-12;  // on |dE/dd| in units of mu0 Ms^2 V / R
  int max_iterations = 2000;
  double max_step = 0.25;         // largest move per iteration, in units of R
  double step_tolerance = 1e-13;  // position resolution relative to |d|: a gradient that a
                                  // displacement this small produces counts as converged
};

struct RelaxResult {
  Eigen::Vector3d separation;  // d = r1 - r2 in metres
  int iterations = 0;
  bool converged = false;
  // Estimate of the distance to the minimum in metres: the last step taken (Newton converges
  // quadratically, so it bounds what is left), or the width of the verified bracket.
  double position_error = 0.0;
};

// Local energy minimisation from a starting configuration, so that a field sweep follows its
// branch (Section 2.4). The single-spring model relaxes only S along the fixed pair axis x (it
// has no rotational restoring force, Section 2.4); the three-spring model relaxes S and the
// rotation angle theta in the plane of the field and the zero-field axis. Method: Newton's
// method on the exact gradient, negative curvature flipped to descend (saddle-free Newton),
// steps capped at max_step and accepted by an Armijo line search, so the energy never increases
// and a pair cannot tunnel through the overlap penalty. A state counts as converged only when
// the gradient is below tolerance or verified to change sign across the minimum (no false
// convergence at the WCA wall); a three-spring pair resting on the wall whose step into it is
// rejected rolls at fixed S until the rotation converges. (The text used nonlinear conjugate
// gradients; Newton reaches the same local minimum in a handful of iterations.)
RelaxResult relax(const PairEnergy& energy, SpringModel model, const Eigen::Vector3d& start,
                  const RelaxOptions& options = {});

// Polak-Ribiere+ nonlinear conjugate gradients with a bracketing line search on the directional
// derivative, in the same coordinates and with the same energy. (N = 1: S; N = 2: S, theta.)
template <int N>
RelaxResult relax_conjugate_gradient(const PairEnergy& energy, const Eigen::Vector3d& start_scaled,
                                     const RelaxOptions& options);

}  // namespace mresim::pair
