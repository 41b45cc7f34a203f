// Where a strain run's loaded steps start (protocols/load_step_start.hpp): the predictions'
// formulas, and on a small shear run that the predicted starts reach the same states as the
// original's start in fewer iterations, are recorded per step, keep the point their next secant
// passes through, and resume bit for bit.

#include "mresim/mess/protocols/load_step_start.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "../../support/temp_dir.hpp"
#include "../support/checkpoint_round_trip.hpp"
#include "../support/mess_test_support.hpp"
#include "../support/small_runs.hpp"
#include "../support/start_comparison.hpp"
#include "mresim/mess/outputs/checkpoint.hpp"
#include "mresim/mess/profile/model_profile.hpp"
#include "mresim/mess/protocols/protocol_runner.hpp"

namespace mresim::mess_protocol {
namespace {

using mess::BoundaryConstraints;
using testing::spec_of;

Eigen::Matrix3Xd linear_state(const Eigen::Matrix3Xd& zero, const Eigen::Matrix3Xd& slope,
                              double c) {
  return zero + c * slope;
}

TEST(LoadStepStart, SecantIsExactForALinearResponse) {
  const Eigen::Matrix3Xd zero = Eigen::Matrix3Xd::Random(3, 50);
  const Eigen::Matrix3Xd slope = Eigen::Matrix3Xd::Random(3, 50);
  // Unevenly spaced strain coordinates, c_0 != 0 (e.g. a shifted measure).
  const double c0 = 0.1;
  const double c1 = 0.35;
  const double c2 = 0.5;
  const Eigen::Matrix3Xd predicted =
      secant_start(linear_state(zero, slope, c1), linear_state(zero, slope, c0), c2, c1, c0);
  EXPECT_LT((predicted - linear_state(zero, slope, c2)).cwiseAbs().maxCoeff(), 1e-14);
}

TEST(LoadStepStart, SecantOfAQuadraticResponseMissesByItsCurvature) {
  // x(c) = x0 + c d + c^2 e from c0 = 0: the secant through 0 and c1 predicts c2 with the error
  // c2 (c2 - c1) e, which the prediction must show (it is not the state itself).
  const Eigen::Matrix3Xd x0 = Eigen::Matrix3Xd::Random(3, 7);
  const Eigen::Matrix3Xd d = Eigen::Matrix3Xd::Random(3, 7);
  const Eigen::Matrix3Xd e = Eigen::Matrix3Xd::Random(3, 7);
  const auto x = [&](double c) -> Eigen::Matrix3Xd { return x0 + c * d + c * c * e; };
  const Eigen::Matrix3Xd predicted = secant_start(x(0.02), x(0.0), 0.03, 0.02, 0.0);
  const Eigen::Matrix3Xd expected_error = 0.03 * (0.03 - 0.02) * e;
  EXPECT_LT(((x(0.03) - predicted) - expected_error).cwiseAbs().maxCoeff(), 1e-15);
}

TEST(LoadStepStart, NeighbourFieldAddsItsResponseToTheZeroLoadState) {
  const Eigen::Matrix3Xd zero = Eigen::Matrix3Xd::Random(3, 9);
  const Eigen::Matrix3Xd neighbour_zero = Eigen::Matrix3Xd::Random(3, 9);
  const Eigen::Matrix3Xd response = Eigen::Matrix3Xd::Random(3, 9);
  const Eigen::Matrix3Xd predicted =
      neighbour_field_start(zero, neighbour_zero + response, neighbour_zero);
  EXPECT_LT((predicted - (zero + response)).cwiseAbs().maxCoeff(), 1e-15);
}

TEST(LoadStepStart, RefusesMismatchedArraysAndDegenerateCoordinates) {
  const Eigen::Matrix3Xd a = Eigen::Matrix3Xd::Zero(3, 4);
  const Eigen::Matrix3Xd b = Eigen::Matrix3Xd::Zero(3, 5);
  EXPECT_THROW((void)secant_start(a, b, 0.2, 0.1, 0.0), std::invalid_argument);
  EXPECT_THROW((void)secant_start(a, a, 0.2, 0.1, 0.1), std::invalid_argument);
  EXPECT_THROW((void)secant_start(a, a, std::numeric_limits<double>::quiet_NaN(), 0.1, 0.0),
               std::invalid_argument);
  EXPECT_THROW((void)neighbour_field_start(a, b, a), std::invalid_argument);
  EXPECT_THROW((void)neighbour_field_start(a, a, b), std::invalid_argument);
}

// Two n_d = 1 particles in a 6 x 6 x 10 cell box, faces held, 0.1 T along z, M solved once.
mess::MessSystem guarded_system() {
  const mess::ModelProfile& profile = mess::model_profile("physical");
  mess::MessSystem system = mess::MessSystem::make(
      mess::testing::small_lattice(profile, {6, 6, 10}, {{2, 2, 2}, {3, 3, 6}}),
      mess::testing::tesla(0.0, 0.0, 0.1), profile);
  BoundaryConstraints held = BoundaryConstraints::none(system.node_count());
  for (const lattice::Face f : {lattice::Face::left, lattice::Face::right, lattice::Face::front,
                                lattice::Face::back, lattice::Face::bottom, lattice::Face::top}) {
    held.fix_face(system.lattice().shape, f, system.lattice().positions);
  }
  system.set_constraints(std::move(held));
  (void)system.evaluate(nullptr);  // M solved: the history a step starts from
  return system;
}

TEST(LoadStepStart, AHigherCandidateLeavesTheSystemAsItWas) {
  mess::MessSystem system = guarded_system();
  const Eigen::Matrix3Xd positions = system.positions();
  const Eigen::Matrix3Xd magnetization = system.magnetizations();
  // Every node moved by up to 0.3 l_e at random: the springs and cells strained.
  Eigen::Matrix3Xd candidate =
      positions + 0.3 * system.length_scale() * Eigen::Matrix3Xd::Random(3, positions.cols());
  const Eigen::Matrix3Xd offered = candidate;
  EXPECT_FALSE(take_if_not_higher(system, candidate));
  EXPECT_EQ(system.positions(), positions);
  EXPECT_EQ(system.magnetizations(), magnetization);
  EXPECT_EQ(candidate.cols(), offered.cols());
}

TEST(LoadStepStart, ALowerCandidateIsTakenWithItsHeldCoordinatesFromTheConstraints) {
  mess::MessSystem system = guarded_system();
  const Eigen::Matrix3Xd rest = system.positions();
  // The start: the rest lattice strained at random; the candidate: the rest lattice (lower),
  // but with every node, held ones too, shifted by a tiny amount the constraints undo.
  Eigen::Matrix3Xd start =
      rest + 0.2 * system.length_scale() * Eigen::Matrix3Xd::Random(3, rest.cols());
  system.set_positions(start);
  Eigen::Matrix3Xd candidate = rest.array() + 1e-3 * system.length_scale();
  EXPECT_TRUE(take_if_not_higher(system, candidate));
  const mess::BoundaryConstraints& held = system.constraints();
  for (Eigen::Index n = 0; n < rest.cols(); ++n) {
    for (int a = 0; a < 3; ++a) {
      const double expected =
          held.is_fixed(n, a) ? rest(a, n) : rest(a, n) + 1e-3 * system.length_scale();
      ASSERT_EQ(system.positions()(a, n), expected) << "node " << n << " axis " << a;
    }
  }
  EXPECT_THROW((void)take_if_not_higher(system, candidate = Eigen::Matrix3Xd::Zero(3, 2)),
               std::invalid_argument);
}

TEST(LoadStepStart, TheLowestOfSeveralCandidatesIsTakenWithItsMagnetization) {
  mess::MessSystem system = guarded_system();
  const Eigen::Matrix3Xd rest = system.positions();
  const double l_e = system.length_scale();
  const Eigen::Matrix3Xd start = rest + 0.2 * l_e * Eigen::Matrix3Xd::Random(3, rest.cols());
  system.set_positions(start);
  const Eigen::Matrix3Xd own = system.positions();  // with the held coordinates put on
  const Eigen::Matrix3Xd history = system.magnetizations();
  // What the system holds after evaluating the rest lattice from the same M history.
  mess::MessSystem reference = system;
  reference.set_positions(rest);
  reference.set_magnetizations(history);
  (void)reference.evaluate(nullptr);

  // The rest lattice (lowest) between two lesser strains of it: taken, though not the last.
  std::vector<Eigen::Matrix3Xd> candidates = {
      rest + 0.05 * l_e * Eigen::Matrix3Xd::Random(3, rest.cols()), rest,
      rest + 0.02 * l_e * Eigen::Matrix3Xd::Random(3, rest.cols())};
  const std::vector<Eigen::Matrix3Xd> offered = candidates;
  ASSERT_EQ(take_lowest(system, candidates), 1);
  EXPECT_EQ(system.positions(), reference.positions());
  EXPECT_EQ(system.magnetizations(), reference.magnetizations());
  // The others are left as offered (their held coordinates from the constraints, which they
  // already had); the taken one's entry holds the system's own start.
  EXPECT_EQ(candidates[2].cols(), offered[2].cols());
  EXPECT_EQ(candidates[1], own);

  // Equal potentials: the earlier candidate.
  system.set_positions(start);
  system.set_magnetizations(history);
  std::vector<Eigen::Matrix3Xd> twins = {rest, rest};
  EXPECT_EQ(take_lowest(system, twins), 0);

  // None below the system's own: nothing changes, bit for bit.
  system.set_positions(rest);
  system.set_magnetizations(history);
  (void)system.evaluate(nullptr);
  const Eigen::Matrix3Xd magnetization = system.magnetizations();
  std::vector<Eigen::Matrix3Xd> higher = {offered[0], offered[2]};
  EXPECT_EQ(take_lowest(system, higher), -1);
  EXPECT_EQ(system.positions(), rest);
  EXPECT_EQ(system.magnetizations(), magnetization);
}

// The small pair (support/small_runs.hpp) sheared at the fields `magnitudes` (T, a TOML
// array) through four strains; `start`: solver.load_step_start (empty: the default).
std::string sheared_pair(const std::string& magnitudes, const std::string& start) {
  return std::string("[run]\ntype = \"mess_strain\"\n") + testing::kSmallModel +
         "\n[field]\nmagnitudes = " + magnitudes +
         "\n\n[strain]\nkind = \"shear\"\nnormal = \"z\"\ndirection = \"x\"\n"
         "max = 0.02\nsteps = 4\n" +
         (start.empty() ? "" : "\n[solver]\nload_step_start = \"" + start + "\"\n");
}

// At two fields (10 steps, step n = 2 k + f).
std::string small_shear(const std::string& start) { return sheared_pair("[0.0, 0.05]", start); }

TEST(LoadStepStart, PredictedStartsReachTheOriginalsStatesInFewerIterations) {
  const std::vector<StepRecord> previous = testing::records_of_run(small_shear("previous"));
  const std::vector<StepRecord> predicted =
      testing::records_of_run(small_shear(""));  // the default
  ASSERT_EQ(previous.size(), 10U);
  ASSERT_EQ(predicted.size(), previous.size());

  // Step n = k F + f (F = 2): the first step from the lattice; the zero strains and the first
  // strain at the first field from the previous state; the first strain at the second field
  // from the first field's response; later strains on the secant, at the second field
  // corrected by the first field's miss.
  const std::vector<std::string> expected_start = {
      step_start::kInitialLattice, step_start::kPrevious,        step_start::kPrevious,
      step_start::kNeighbourField, step_start::kSecant,          step_start::kCorrectedSecant,
      step_start::kSecant,         step_start::kCorrectedSecant, step_start::kSecant,
      step_start::kCorrectedSecant};
  std::int64_t iterations_previous = 0;
  std::int64_t iterations_predicted = 0;
  for (std::size_t i = 0; i < previous.size(); ++i) {
    const StepRecord& a = previous[i];
    const StepRecord& b = predicted[i];
    EXPECT_EQ(a.start, i == 0 ? step_start::kInitialLattice : step_start::kPrevious);
    EXPECT_EQ(b.start, expected_start[i]) << "step " << i;
    testing::expect_same_minimum(a, b, i, std::abs(a.energies.total()));
    iterations_previous += a.iterations;
    iterations_predicted += b.iterations;
  }
  EXPECT_LT(iterations_predicted, iterations_previous);
}

TEST(LoadStepStart, ResumedFromACheckpointEqualsTheUninterruptedRun) {
  const std::string toml = small_shear("");
  const mess_config::MessSpec spec = spec_of(toml);
  const std::vector<StepRecord> full = testing::records_of_run(toml);

  // Interrupted before the neighbour-field step 3 and the secant steps after it; and before
  // step 7, the second field's third strain, whose secant and those after it pass through
  // the checkpoint's results two strains back (ProtocolState::earlier_load_results).
  for (const std::size_t done : {3U, 7U}) {
    const mresim::testing::TempDir dir;
    ProtocolRunner second(spec);
    ProtocolState resumed = testing::resumed_after(toml, done, dir / "checkpoint.h5", second);
    if (done == 7) {
      ASSERT_EQ(resumed.earlier_load_results.size(), 2U);
      EXPECT_GT(resumed.earlier_load_results[0].cols(), 0);
      EXPECT_GT(resumed.earlier_load_results[1].cols(), 0);
    }
    second.run(resumed, nullptr);
    testing::expect_same_records(resumed.records, full);
  }
}

// From the third strain on, a step's secant passes through its field's result two strains back
// (x_{k-2}, not the zero-strain state): each loaded step keeps its start, the field's result at
// the strain before, for the field's next strain. Through the zero-strain state, a contact
// formed at an earlier strain would be carried on (the Fig. 4.25 helix at 10 and 20 mT).
TEST(LoadStepStart, EachLoadedStepKeepsItsStartForTheFieldsNextSecant) {
  const mess_config::MessSpec spec = spec_of(small_shear(""));
  ProtocolRunner runner(spec);
  ASSERT_TRUE(runner.keeps_earlier_load_results());
  ProtocolState state = runner.initial_state();
  ASSERT_EQ(state.earlier_load_results.size(), 2U);
  while (state.next_step < runner.steps().size()) {
    const StepSpec& step = runner.steps()[state.next_step];
    const Eigen::Matrix3Xd start = state.slots[step.field_index].positions.load();
    runner.run_next_step(state);
    if (step.load_index == 0) {
      EXPECT_EQ(state.earlier_load_results[step.field_index].cols(), 0) << state.next_step;
      continue;
    }
    ASSERT_GT(start.cols(), 0);
    EXPECT_TRUE(state.earlier_load_results[step.field_index].load() == start)
        << "step " << state.next_step - 1;
  }
  // "previous" keeps none.
  const ProtocolRunner original(spec_of(small_shear("previous")));
  EXPECT_FALSE(original.keeps_earlier_load_results());
  EXPECT_TRUE(original.initial_state().earlier_load_results.empty());
}

// At three fields (15 steps, step n = 3 k + f).
std::string three_field_shear(const std::string& start) {
  return sheared_pair("[0.0, 0.05, 0.1]", start);
}

// From the second strain on, a later field's step is offered its secant corrected by the
// previous field's miss (and, from the third field, by that miss extrapolated in the field):
// the lowest start is taken, and the steps reach the original's states.
TEST(LoadStepStart, LaterFieldsStartFromTheSecantCorrectedByThePreviousFieldsMiss) {
  const std::vector<StepRecord> previous = testing::records_of_run(three_field_shear("previous"));
  const std::vector<StepRecord> secant = testing::records_of_run(three_field_shear("secant"));
  const std::vector<StepRecord> predicted = testing::records_of_run(three_field_shear(""));
  ASSERT_EQ(previous.size(), 15U);
  ASSERT_EQ(predicted.size(), previous.size());
  ASSERT_EQ(secant.size(), previous.size());
  std::int64_t iterations_secant = 0;
  std::int64_t iterations_predicted = 0;
  for (std::size_t i = 0; i < previous.size(); ++i) {
    const StepSpec& step = predicted[i].step;
    const double energy_scale = std::abs(previous[i].energies.total());
    testing::expect_same_minimum(previous[i], predicted[i], i, energy_scale);
    testing::expect_same_minimum(previous[i], secant[i], i, energy_scale);
    if (step.load_index == 0) continue;
    // "secant": the prediction without the corrections.
    const std::string first_strain =
        step.field_index == 0 ? step_start::kPrevious : step_start::kNeighbourField;
    EXPECT_EQ(secant[i].start, step.load_index == 1 ? first_strain : step_start::kSecant)
        << "step " << i;
    if (step.load_index < 2) continue;
    // The first field has no field before it at this strain: its plain secant.
    EXPECT_EQ(predicted[i].start,
              step.field_index == 0 ? step_start::kSecant : step_start::kCorrectedSecant)
        << "step " << i;
    if (step.field_index > 0) {
      iterations_secant += secant[i].iterations;
      iterations_predicted += predicted[i].iterations;
    }
  }
  EXPECT_LT(iterations_predicted, iterations_secant);
}

// A step keeps its miss, x_k(f) - S_k(f), only for the next field's step at the same strain,
// with the miss of the step before it; what it keeps is what secant_miss_of recomputes from the
// steps' results (a rebuilt state, restart/saved_run.hpp), bit for bit.
TEST(LoadStepStart, EachKeptMissIsTheStepsResultMinusItsSecant) {
  const mess_config::MessSpec spec = spec_of(three_field_shear(""));
  ProtocolRunner runner(spec);
  ProtocolState state = runner.initial_state();
  std::vector<Eigen::Matrix3Xd> results;
  Eigen::Matrix3Xd last_miss;
  std::size_t kept = 0;
  while (state.next_step < runner.steps().size()) {
    const std::size_t i = state.next_step;
    runner.run_next_step(state);
    results.push_back(state.slots[runner.steps()[i].field_index].positions.load());
    if (!runner.next_step_takes_miss(i)) {
      EXPECT_EQ(state.secant_miss.cols(), 0) << "step " << i;
      EXPECT_EQ(state.earlier_secant_miss.cols(), 0) << "step " << i;
      last_miss.resize(3, 0);
      continue;
    }
    std::vector<Eigen::Matrix3Xd> sources;
    for (const std::size_t k : runner.secant_miss_sources(i)) sources.push_back(results.at(k));
    const Eigen::Matrix3Xd miss = runner.secant_miss_of(i, sources);
    EXPECT_TRUE(state.secant_miss.load() == miss) << "step " << i;
    EXPECT_GT(miss.cwiseAbs().maxCoeff(), 0.0) << "step " << i;
    ASSERT_EQ(state.earlier_secant_miss.cols(), last_miss.cols()) << "step " << i;
    EXPECT_TRUE(state.earlier_secant_miss.load() == last_miss) << "step " << i;
    last_miss = miss;
    ++kept;
  }
  // Strains 2 to 4 at the first two fields.
  EXPECT_EQ(kept, 6U);
}

TEST(LoadStepStart, ResumedWithTheMissesInTheCheckpointEqualsTheUninterruptedRun) {
  const std::string toml = three_field_shear("");
  const mess_config::MessSpec spec = spec_of(toml);
  const std::vector<StepRecord> full = testing::records_of_run(toml);
  // After step 6 (the first field at the second strain) the state holds its miss; after step 7
  // (the second field) that one and step 7's, which step 8 extrapolates in the field.
  for (const std::size_t done : {7U, 8U}) {
    const mresim::testing::TempDir dir;
    ProtocolRunner second(spec);
    ProtocolState resumed = testing::resumed_after(toml, done, dir / "checkpoint.h5", second);
    EXPECT_GT(resumed.secant_miss.cols(), 0) << done;
    EXPECT_EQ(resumed.earlier_secant_miss.cols() > 0, done == 8) << done;
    second.run(resumed, nullptr);
    testing::expect_same_records(resumed.records, full);
  }
}

}  // namespace
}  // namespace mresim::mess_protocol
