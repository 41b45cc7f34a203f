// The relaxation observer (relaxation_observer.hpp) sees the iterations of the minimiser and
// of the leapfrog, and a relaxation watched by one ends bit for bit where an unwatched one does:
// progress reports never change the numbers.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <vector>

#include "../support/mess_test_support.hpp"
#include "mresim/mess/solvers/leapfrog.hpp"
#include "mresim/mess/solvers/minimiser.hpp"

namespace mess = mresim::mess;
namespace lat = mresim::lattice;
using mess::testing::small_lattice;
using mess::testing::tesla;

namespace {

// Two particles in a field, all faces held: a relaxation with particle forces and M re-solves.
mess::MessSystem pair_in_a_field() {
  const mess::ModelProfile& profile = mess::model_profile("physical");
  mess::MessSystem sys = mess::MessSystem::make(
      small_lattice(profile, {7, 7, 12}, {{3, 3, 3}, {3, 3, 8}}), tesla(0.0, 0.0, 0.1), profile);
  mess::BoundaryConstraints c = mess::BoundaryConstraints::none(sys.lattice().node_count());
  for (const lat::Face f : {lat::Face::bottom, lat::Face::top}) {
    c.fix_face(sys.lattice().shape, f, sys.lattice().positions);
  }
  sys.set_constraints(c);
  return sys;
}

struct Seen {
  std::vector<std::int64_t> iterations;
  std::vector<double> residuals;
  mess::RelaxationObserver observer() {
    return [this](const mess::RelaxationIteration& it) {
      iterations.push_back(it.iteration);
      residuals.push_back(it.residual);
    };
  }
};

}  // namespace

TEST(RelaxationObserver, SeesTheMinimiserWithoutChangingIt) {
  for (const mess::MinimiserMethod method :
       {mess::MinimiserMethod::lbfgs, mess::MinimiserMethod::fire}) {
    mess::MinimiserOptions options;
    options.method = method;
    options.force_tolerance = 1e-7;
    mess::MessSystem plain = pair_in_a_field();
    const mess::MinimiserResult a = mess::minimise(plain, options);

    Seen seen;
    options.observer = seen.observer();
    mess::MessSystem watched = pair_in_a_field();
    const mess::MinimiserResult b = mess::minimise(watched, options);

    EXPECT_EQ(b.iterations, a.iterations) << mess::to_string(method);
    EXPECT_EQ(b.max_force, a.max_force);
    EXPECT_TRUE((watched.positions().array() == plain.positions().array()).all());
    EXPECT_TRUE((watched.magnetizations().array() == plain.magnetizations().array()).all());
    // One report per convergence check, numbered from 1; the forces are the minimiser's (N).
    ASSERT_GE(seen.iterations.size(), static_cast<std::size_t>(a.iterations));
    for (std::size_t k = 0; k < seen.iterations.size(); ++k) {
      EXPECT_EQ(seen.iterations[k], static_cast<std::int64_t>(k) + 1);
    }
    EXPECT_GT(seen.residuals.front(), seen.residuals.back());
    EXPECT_LE(seen.residuals.back(), options.force_tolerance * b.force_scale);
  }
}

// A particle-free block with its boundary sheared affinely (as in relaxation_test.cpp).
mess::MessSystem sheared_block() {
  const mess::ModelProfile& profile = mess::model_profile("physical");
  const lat::Lattice l = small_lattice(profile, {5, 5, 5});
  Eigen::Matrix3Xd affine = l.positions;
  affine.row(0) += 1e-3 * l.positions.row(2);
  mess::MessSystem sys = mess::MessSystem::make(l, Eigen::Vector3d::Zero(), profile);
  mess::BoundaryConstraints c = mess::BoundaryConstraints::none(l.node_count());
  for (const lat::Face f : {lat::Face::left, lat::Face::right, lat::Face::front, lat::Face::back,
                            lat::Face::bottom, lat::Face::top}) {
    c.fix_face(l.shape, f, affine);
  }
  sys.set_constraints(c);
  return sys;
}

TEST(RelaxationObserver, SeesTheLeapfrogEveryDifferenceIntervalWithoutChangingIt) {
  mess::LeapfrogOptions options;
  options.steps_per_round = 1000;
  options.max_rounds = 4;
  options.tolerance = 1e-9;
  mess::MessSystem plain = sheared_block();
  const mess::LeapfrogResult a = mess::relax_leapfrog(plain, options);

  Seen seen;
  options.observer = seen.observer();
  mess::MessSystem watched = sheared_block();
  const mess::LeapfrogResult b = mess::relax_leapfrog(watched, options);

  EXPECT_EQ(b.steps, a.steps);
  EXPECT_TRUE((watched.positions().array() == plain.positions().array()).all());
  const auto interval = static_cast<std::size_t>(options.difference_interval);
  ASSERT_EQ(seen.iterations.size(), static_cast<std::size_t>(a.steps) / interval);
  EXPECT_EQ(seen.iterations.front(), options.difference_interval);
  // At the end of a round the report is the round's own mean |a|.
  const auto per_round = static_cast<std::size_t>(options.steps_per_round) / interval;
  EXPECT_EQ(seen.residuals[per_round - 1], b.history.front().mean_abs_acceleration);
}
