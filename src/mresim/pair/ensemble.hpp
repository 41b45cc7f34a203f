#pragma once

#include <vector>

#include "mresim/pair/hysteresis.hpp"

namespace mresim::pair {

// Ensemble of pairs with a distribution of zero-field separations (Section 3.6, Fig. 3.5):
// the magnetization along the field averaged over loops at each S0, weighted.

// Gaussian weights exp(-(S0 - mean)^2 / (2 sd^2)) at the given separations, normalised to sum 1.
std::vector<double> gaussian_weights(const std::vector<double>& separations, double mean,
                                     double standard_deviation);

// A magnetization loop: field, branch (0 initial rise, 1 descent, 2 final rise) and M/Ms along
// the field, in sweep order.
struct MagnetizationLoop {
  std::vector<double> field;
  std::vector<int> branch;
  std::vector<double> magnetization;
};

MagnetizationLoop magnetization_loop(const HysteresisLoop& loop);

// Weighted average of the loops of `base` with its S0 replaced by each separation. When the
// springs come from a shear modulus (three-spring Puljiz constants depend on S0), pass
// `springs_at` to rebuild them per separation. Loops run in parallel; the sum is taken in a
// fixed order, so the result does not depend on the thread count.
struct EnsembleResult {
  MagnetizationLoop average;
  std::vector<MagnetizationLoop> members;  // one per separation, same order
};
EnsembleResult ensemble_average(const std::vector<PairSystem>& members,
                                const std::vector<double>& weights, const SweepOptions& sweep);

// Loop widening Delta(M/Ms)(H) (Section 3.5, Fig. 3.1b): descending minus final ascending branch
// at each H >= 0 of the sweep grid.
struct LoopWidening {
  std::vector<double> field;
  std::vector<double> widening;
};
LoopWidening loop_widening(const MagnetizationLoop& loop);

// Differential susceptibility d(M/Ms)/dB along each branch (1/T) by centred differences
// (one-sided at the branch ends); optionally a five-point moving average as in Fig. 3.1 and
// 3.3 (shrinking at the branch ends). Same order and length as the loop.
std::vector<double> differential_susceptibility(const MagnetizationLoop& loop,
                                                bool five_point_smoothing);

// Five-point moving average of a series (window shrinks at the ends).
std::vector<double> five_point_average(const std::vector<double>& values);

}  // namespace mresim::pair
