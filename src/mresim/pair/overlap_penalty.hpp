#pragma once

#include "mresim/pair/pair_system.hpp"

namespace mresim::pair {

// Energy (J) and its derivatives dE/dS, d2E/dS2 of the overlap penalty at centre distance S (m).
struct PenaltyValue {
  double energy = 0.0;
  double derivative = 0.0;
  double second_derivative = 0.0;  // J/m^2, for the relaxation's Newton steps
};

PenaltyValue overlap_penalty(const OverlapPenalty& penalty, double radius, double separation);

// The separation below which a pair counts as clustered (in contact): 2R for tanh, the WCA
// cut-off for WCA (the text's definition of the clustered state in Section 2.5.3).
double contact_separation(const OverlapPenalty& penalty, double radius);

}  // namespace mresim::pair
