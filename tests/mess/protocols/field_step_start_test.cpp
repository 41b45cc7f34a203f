// Where a field step starts (protocols/load_step_start.hpp, solver.field_step_start): the field
// secant's formula, and on small runs that the predicted starts are recorded per step, reach the
// original start's states in fewer iterations, and resume bit for bit.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "../../support/temp_dir.hpp"
#include "../support/checkpoint_round_trip.hpp"
#include "../support/small_runs.hpp"
#include "../support/start_comparison.hpp"
#include "mresim/mess/protocols/load_step_start.hpp"
#include "mresim/mess/protocols/protocol_runner.hpp"

namespace mresim::mess_protocol {
namespace {

using testing::spec_of;

TEST(FieldStepStart, SecantIsExactForAResponseLinearInTheField) {
  const Eigen::Matrix3Xd rest = Eigen::Matrix3Xd::Random(3, 40);
  const Eigen::Matrix3Xd slope = Eigen::Matrix3Xd::Random(3, 40);
  // Fields along one axis, unevenly spaced; the response is linear in the component along it.
  const Eigen::Vector3d axis = Eigen::Vector3d(1.0, -2.0, 0.5).normalized();
  const auto state = [&](double b) -> Eigen::Matrix3Xd { return rest + b * slope; };
  const double b0 = 0.01;
  const double b1 = 0.025;
  const double b2 = 0.045;
  const Eigen::Matrix3Xd predicted =
      field_secant_start(state(b1), state(b0), b2 * axis, b1 * axis, b0 * axis);
  EXPECT_LT((predicted - state(b2)).cwiseAbs().maxCoeff(), 1e-14);
}

TEST(FieldStepStart, WhereTheLoopTurnsTheSecantReturnsToTheFieldBefore) {
  // 35 -> 40 mT, then back to 35 mT: r = -1, so the start is the 35 mT result.
  const Eigen::Matrix3Xd at35 = Eigen::Matrix3Xd::Random(3, 11);
  const Eigen::Matrix3Xd at40 = Eigen::Matrix3Xd::Random(3, 11);
  const Eigen::Vector3d z = Eigen::Vector3d::UnitZ();
  const Eigen::Matrix3Xd predicted = field_secant_start(at40, at35, 0.035 * z, 0.04 * z, 0.035 * z);
  EXPECT_LT((predicted - at35).cwiseAbs().maxCoeff(), 1e-15);
}

TEST(FieldStepStart, ProjectsTheFieldChangeOnThePreviousChange) {
  // A change perpendicular to the previous one extrapolates nothing: r = 0.
  const Eigen::Matrix3Xd previous = Eigen::Matrix3Xd::Random(3, 5);
  const Eigen::Matrix3Xd earlier = Eigen::Matrix3Xd::Random(3, 5);
  const Eigen::Matrix3Xd predicted =
      field_secant_start(previous, earlier, Eigen::Vector3d(0.01, 0.02, 0.0),
                         Eigen::Vector3d(0.0, 0.02, 0.0), Eigen::Vector3d(0.0, 0.01, 0.0));
  EXPECT_LT((predicted - previous).cwiseAbs().maxCoeff(), 1e-15);
}

TEST(FieldStepStart, RefusesMismatchedArraysAndDegenerateFields) {
  const Eigen::Matrix3Xd a = Eigen::Matrix3Xd::Zero(3, 4);
  const Eigen::Matrix3Xd b = Eigen::Matrix3Xd::Zero(3, 5);
  const Eigen::Vector3d z = Eigen::Vector3d::UnitZ();
  EXPECT_THROW((void)field_secant_start(a, b, 0.02 * z, 0.01 * z, 0.0 * z), std::invalid_argument);
  EXPECT_THROW((void)field_secant_start(a, a, 0.02 * z, 0.01 * z, 0.01 * z), std::invalid_argument);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW((void)field_secant_start(a, a, nan * z, 0.01 * z, 0.0 * z), std::invalid_argument);
}

// The small pair's field loop 0 -> 30 -> -30 -> 30 mT in 10 mT steps (16 steps; the pair does
// not reach contact), with the given solver.field_step_start ("": the default).
std::string small_field_loop(const std::string& start) {
  return testing::small_hysteresis(0.03, 3) +
         (start.empty() ? "" : "\n[solver]\nfield_step_start = \"" + start + "\"\n");
}

TEST(FieldStepStart, PredictedStartsReachTheOriginalsStatesInFewerIterations) {
  const std::vector<StepRecord> previous = testing::records_of_run(small_field_loop("previous"));
  const std::vector<StepRecord> predicted =
      testing::records_of_run(small_field_loop(""));  // the default
  ASSERT_EQ(previous.size(), 16U);
  ASSERT_EQ(predicted.size(), previous.size());

  std::int64_t iterations_previous = 0;
  std::int64_t iterations_predicted = 0;
  int secant_starts = 0;
  // Energies compared on the loop's scale: at zero field the total is a rounding residue.
  double energy_scale = 0.0;
  for (const StepRecord& a : previous) {
    energy_scale = std::max(energy_scale, std::abs(a.energies.total()));
  }
  for (std::size_t i = 0; i < previous.size(); ++i) {
    const StepRecord& a = previous[i];
    const StepRecord& b = predicted[i];
    const std::string first = i == 0 ? step_start::kInitialLattice : step_start::kPrevious;
    EXPECT_EQ(a.start, first) << "step " << i;
    // The first two fields have no secant; from the third on it is made, and kept or rejected.
    if (i < 2) {
      EXPECT_EQ(b.start, first) << "step " << i;
    } else {
      EXPECT_TRUE(b.start == step_start::kFieldSecant || b.start == step_start::kPredictionRejected)
          << "step " << i << ": " << b.start;
    }
    secant_starts += b.start == step_start::kFieldSecant ? 1 : 0;
    testing::expect_same_minimum(a, b, i, energy_scale);
    iterations_previous += a.iterations;
    iterations_predicted += b.iterations;
  }
  // Apart, the pair's response is smooth in the field: the secant is kept at most steps.
  EXPECT_GE(secant_starts, 8);
  EXPECT_LT(iterations_predicted, iterations_previous);
}

TEST(FieldStepStart, TheLeapfrogKeepsTheOriginalsStart) {
  const mess_config::MessSpec spec =
      spec_of(testing::small_hysteresis(0.03, 3) + "\n[solver]\nmethod = \"leapfrog\"\n");
  EXPECT_EQ(spec.solver.field_step_start, mess_config::FieldStepStart::previous);
  EXPECT_FALSE(ProtocolRunner(spec).keeps_earlier_field_result());
  EXPECT_EQ(spec_of(small_field_loop("")).solver.field_step_start,
            mess_config::FieldStepStart::extrapolated);
}

TEST(FieldStepStart, ResumedFromACheckpointEqualsTheUninterruptedRun) {
  const std::string toml = small_field_loop("");
  const std::vector<StepRecord> full = testing::records_of_run(toml);

  const mresim::testing::TempDir dir;
  ProtocolRunner second(spec_of(toml));
  // Interrupted after four steps: the next secant needs the result kept before the slot's.
  ProtocolState resumed = testing::resumed_after(toml, 4, dir / "checkpoint.h5", second);
  ASSERT_GT(resumed.earlier_field_result.cols(), 0);
  second.run(resumed, nullptr);
  testing::expect_same_records(resumed.records, full);
}

TEST(FieldStepStart, AStrainRunsZeroStrainStepsUseTheZeroStrainResults) {
  // Three fields at zero strain, then one strain: the third field's zero-strain step is on the
  // secant through the first two fields' zero-strain results (`references`).
  const std::string toml = std::string("[run]\ntype = \"mess_strain\"\n") + testing::kSmallModel +
                           "\n[field]\nmagnitudes = [0.0, 0.01, 0.02]\n"
                           "\n[strain]\nkind = \"shear\"\nnormal = \"z\"\ndirection = \"x\"\n"
                           "max = 0.01\nsteps = 1\n";
  const mess_config::MessSpec spec = spec_of(toml);
  EXPECT_FALSE(ProtocolRunner(spec).keeps_earlier_field_result());
  const std::vector<StepRecord> records = testing::records_of_run(toml);
  ASSERT_EQ(records.size(), 6U);
  EXPECT_EQ(records[0].start, step_start::kInitialLattice);
  EXPECT_EQ(records[1].start, step_start::kPrevious);
  EXPECT_EQ(records[2].start, step_start::kFieldSecant);
  for (const StepRecord& r : records) EXPECT_TRUE(r.converged);
}

}  // namespace
}  // namespace mresim::mess_protocol
