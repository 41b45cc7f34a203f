#pragma once

// A look into a running relaxation, for progress reports: the solvers (minimiser.hpp's
// L-BFGS, FIRE and Newton-Krylov, leapfrog.hpp) call the observer as they go with what they
// have computed anyway. It must not change the system; the relaxation's results are the same
// with or without one.

#include <cstdint>
#include <functional>

namespace mresim::mess {

struct RelaxationIteration {
  // Minimisers: convergence checks so far in this call (about one per iteration); leapfrog:
  // time steps so far.
  std::int64_t iteration = 0;
  // Minimisers: the convergence measure, the largest free or net force (N); leapfrog: the mean
  // |acceleration| of the free polymer coordinates (scaled units, as its tolerance).
  double residual = 0.0;
};

// Empty: nobody is watching. Called on the relaxing thread, outside parallel regions.
using RelaxationObserver = std::function<void(const RelaxationIteration&)>;

}  // namespace mresim::mess
