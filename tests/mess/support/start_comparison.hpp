#pragma once

// Helpers of the tests of where a step starts (protocols/load_step_start.hpp): whole small runs,
// and the comparisons of two runs that start their steps differently or were resumed.

#include <gtest/gtest.h>

#include <cstddef>
#include <string>
#include <vector>

#include "mresim/mess/protocols/protocol_runner.hpp"
#include "small_runs.hpp"

namespace mresim::mess_protocol::testing {

// Every step's record of the run `toml`, run to its end on one runner.
inline std::vector<StepRecord> records_of_run(const std::string& toml) {
  ProtocolRunner runner(spec_of(toml));
  ProtocolState state = runner.initial_state();
  runner.run(state, nullptr);
  return state.records;
}

// Step `step` of two runs of the small pair (l_e = 1 um) converged to the same minimum, to well
// within the force tolerance's reach (1e-6 k_eff l_e): centres to 1e-6 l_e, M to 1e-6 Ms, the
// total energies to 1e-6 of `energy_scale` (J).
inline void expect_same_minimum(const StepRecord& a, const StepRecord& b, std::size_t step,
                                double energy_scale) {
  const double l_e = 1e-6;
  const double ms = 1.6e6;  // A/m
  EXPECT_TRUE(a.converged && b.converged) << "step " << step;
  EXPECT_LT((a.centres - b.centres).cwiseAbs().maxCoeff(), 1e-6 * l_e) << "step " << step;
  EXPECT_LT((a.magnetization - b.magnetization).cwiseAbs().maxCoeff(), 1e-6 * ms)
      << "step " << step;
  EXPECT_NEAR(a.energies.total(), b.energies.total(), 1e-6 * energy_scale) << "step " << step;
}

// A resumed run's records are the uninterrupted run's, bit for bit, starts included.
inline void expect_same_records(const std::vector<StepRecord>& resumed,
                                const std::vector<StepRecord>& full) {
  ASSERT_EQ(resumed.size(), full.size());
  for (std::size_t i = 0; i < full.size(); ++i) {
    EXPECT_EQ(resumed[i].start, full[i].start) << "step " << i;
    EXPECT_EQ(resumed[i].centres, full[i].centres) << "step " << i;
    EXPECT_EQ(resumed[i].energies.total(), full[i].energies.total()) << "step " << i;
    EXPECT_EQ(resumed[i].iterations, full[i].iterations) << "step " << i;
  }
}

}  // namespace mresim::mess_protocol::testing
