#pragma once

// The pieces the inner minimisations share (minimiser.cpp's L-BFGS and FIRE, newton.cpp's
// Newton-Krylov): the result of one inner minimisation, and the strong-Wolfe line search on
// the scaled objective (relaxation_common.hpp).

#include <Eigen/Core>

#include "mresim/mess/solvers/minimiser.hpp"
#include "mresim/mess/solvers/relaxation_common.hpp"

namespace mresim::mess::detail {

struct InnerResult {
  MinimiserStatus status = MinimiserStatus::max_iterations;
  int iterations = 0;
  double energy_change = 0.0;  // scaled
};

// Ends an inner minimisation that no longer makes progress: `limit` iterations in a row
// without a new smallest gradient component and (when energies are used) without an energy
// decrease beyond the potential's rounding noise (eps times its magnitude).
class StallGuard {
 public:
  StallGuard(const Eigen::VectorXd& g, int limit)
      : best_gradient_(g.cwiseAbs().maxCoeff()), limit_(limit) {}
  // After an accepted iteration with gradient g and energy change `change` (scaled): true
  // when it is stalled.
  bool stalled(const Eigen::VectorXd& g, double change, const Objective& f, bool use_energy);

 private:
  double best_gradient_;
  int limit_;
  int count_ = 0;
};

struct LinePoint {
  double alpha = 0.0;
  double phi = 0.0;   // scaled potential
  double dphi = 0.0;  // directional derivative g . d
  Eigen::VectorXd g;
};

// Strong-Wolfe line search (Nocedal & Wright Alg. 3.5/3.6) along d from u, with a rounding
// slack on the sufficient-decrease test and derivative (secant) interpolation in the zoom.
// `from`: the point at alpha = 0 (its gradient is not used). On success `out` holds the
// accepted point and the system is left at it.
// use_energy = false: forces only (a field that is not exactly a gradient): the energy tests
// are dropped and the search brackets the zero of the slope g(alpha) . d.
bool wolfe_line_search(Objective& f, const Eigen::VectorXd& u, const Eigen::VectorXd& d,
                       const LinePoint& from, double alpha_init, double alpha_max, bool use_energy,
                       LinePoint& out);

}  // namespace mresim::mess::detail
