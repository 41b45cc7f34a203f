// A run keeps the multilevel preconditioner between steps (solver.preconditioner_reuse,
// solvers/preconditioner_cache.hpp) and records which steps built it; a run resumed from a
// checkpoint taken where the next step keeps an earlier step's preconditioner continues bit for
// bit as the uninterrupted run (the checkpoint holds the anchor); distance 0 builds it at every
// step, and the minima are the same.
//
// The multilevel preconditioner is used from 40,000 nodes on, so the pair of the small runs
// (small_runs.hpp, l_e = 1 um) sits here in a 34 um box: 42,875 nodes, a second per step.

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "../../support/temp_dir.hpp"
#include "../support/checkpoint_round_trip.hpp"
#include "../support/small_runs.hpp"
#include "../support/start_comparison.hpp"
#include "mresim/mess/protocols/protocol_runner.hpp"
#include "mresim/mess/solvers/minimiser.hpp"

namespace mresim::mess_protocol {
namespace {

// 0, 4, 8 mT along the pair's axis, 7 um apart: the pair moves by about 25 nm per step, less
// than a distance of 0.1 lattice spacings (100 nm) from the first step's start.
std::string large_box_field_steps(double reuse) {
  std::string model = testing::kSmallModel;
  const std::string box = "size = [9e-6, 9e-6, 17e-6]";
  model.replace(model.find(box), box.size(), "size = [34e-6, 34e-6, 34e-6]");
  return "[run]\ntype = \"mess_hysteresis\"\n" + model +
         "\n[field]\nmax = 0.008\nsteps = 2\nsequence = \"up\"\n"
         "\n[solver]\npreconditioner_reuse = " +
         std::to_string(reuse) + "\n";
}

TEST(PreconditionerReuse, KeptStepsReachTheSameMinimaAndAResumedRunKeepsThemBitForBit) {
  const std::string toml = large_box_field_steps(0.1);
  const mess_config::MessSpec spec = testing::spec_of(toml);
  ASSERT_GE(spec.geometry.node_count(), mess::kMultilevelMinimumNodes);
  EXPECT_EQ(spec.solver.preconditioner_reuse, 0.1);
  const std::vector<StepRecord> kept = testing::records_of_run(toml);
  const std::vector<StepRecord> built = testing::records_of_run(large_box_field_steps(0.0));
  ASSERT_EQ(kept.size(), 3U);
  EXPECT_EQ(kept[0].preconditioner, "built");
  EXPECT_EQ(kept[1].preconditioner, "kept");
  EXPECT_EQ(kept[2].preconditioner, "kept");
  for (std::size_t i = 0; i < kept.size(); ++i) {
    EXPECT_EQ(built[i].preconditioner, "built") << "step " << i;
    // The same minimum whichever preconditioner steered L-BFGS there.
    testing::expect_same_minimum(kept[i], built[i], i, std::abs(built.back().energies.total()));
  }

  // Interrupted after step 1: step 2 keeps the preconditioner built at step 0's start (the
  // initial lattice), 50 nm from its own start, so it needs the anchor.
  const mresim::testing::TempDir dir;
  ProtocolRunner second(spec);
  ProtocolState resumed = testing::resumed_after(toml, 2, dir / "checkpoint.h5", second);
  ASSERT_NE(resumed.preconditioner_anchor, nullptr);
  second.run(resumed, nullptr);
  testing::expect_same_records(resumed.records, kept);
  for (std::size_t i = 0; i < kept.size(); ++i) {
    EXPECT_EQ(resumed.records[i].preconditioner, kept[i].preconditioner) << "step " << i;
  }
}

// The default distance, 0.3 lattice spacings (measured on the full-size helix and Fig. 4.11
// loop, docs/performance.md), is the run files' and the minimiser's alike.
TEST(PreconditionerReuse, DefaultIsThreeTenthsOfALatticeSpacing) {
  std::string toml = large_box_field_steps(0.1);
  toml.erase(toml.find("\n[solver]"));
  EXPECT_EQ(testing::spec_of(toml).solver.preconditioner_reuse, 0.3);
  EXPECT_EQ(mess::MinimiserOptions{}.preconditioner_reuse, 0.3);
}

}  // namespace
}  // namespace mresim::mess_protocol
