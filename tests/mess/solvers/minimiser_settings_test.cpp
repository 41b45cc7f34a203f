// minimise() evaluates under its own rules (magnetization coupling, the seed's conservative
// L-BFGS phase at CentreRule::all_nodes, FIRE's fixed-M frequency estimate), but the system's
// settings() must be the caller's again when it returns or throws (minimiser.hpp).

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <string>

#include "../support/mess_test_support.hpp"
#include "mresim/mess/solvers/minimiser.hpp"

namespace mess = mresim::mess;
namespace lat = mresim::lattice;
using mess::testing::small_lattice;
using mess::testing::tesla;

namespace {

// Every field of MessSettings, so that a change of any of them fails the test.
void expect_same_settings(const mess::MessSettings& a, const mess::MessSettings& b,
                          const std::string& where) {
  EXPECT_EQ(a.elastic.volume_force_factor, b.elastic.volume_force_factor) << where;
  EXPECT_EQ(a.centre_rule, b.centre_rule) << where;
  EXPECT_EQ(a.magnetization_update, b.magnetization_update) << where;
  EXPECT_EQ(a.resolve_distance, b.resolve_distance) << where;
  const auto& m = a.magnetization;
  const auto& n = b.magnetization;
  EXPECT_EQ(m.atol, n.atol) << where;
  EXPECT_EQ(m.rtol, n.rtol) << where;
  EXPECT_EQ(m.demagnetization, n.demagnetization) << where;
  EXPECT_EQ(m.methods, n.methods) << where;
  EXPECT_EQ(m.max_fixed_point_iterations, n.max_fixed_point_iterations) << where;
  EXPECT_EQ(m.stall_window, n.stall_window) << where;
  EXPECT_EQ(m.stall_factor, n.stall_factor) << where;
  EXPECT_EQ(m.max_anderson_iterations, n.max_anderson_iterations) << where;
  EXPECT_EQ(m.anderson_depth, n.anderson_depth) << where;
  EXPECT_EQ(m.max_newton_iterations, n.max_newton_iterations) << where;
  EXPECT_EQ(m.check_stability, n.check_stability) << where;
}

// Two particles one polymer voxel apart in a 5 x 5 x 11 box in a field along z, bottom and top
// held: the relaxation moves them, so every rule minimise() sets is exercised.
mess::MessSystem two_particles(const mess::ModelProfile& profile) {
  mess::MessSystem sys = mess::MessSystem::make(
      small_lattice(profile, {5, 5, 11}, {{2, 2, 3}, {2, 2, 7}}), tesla(0.0, 0.0, 0.3), profile);
  mess::BoundaryConstraints c = mess::BoundaryConstraints::none(sys.lattice().node_count());
  c.fix_face(sys.lattice().shape, lat::Face::bottom, sys.lattice().positions);
  c.fix_face(sys.lattice().shape, lat::Face::top, sys.lattice().positions);
  sys.set_constraints(c);
  // A caller's update rule that minimise() never uses itself, and a non-default distance.
  sys.settings().magnetization_update = mess::MagnetizationUpdate::on_displacement;
  sys.settings().resolve_distance = 2e-3;
  return sys;
}

}  // namespace

// The seed profile (centre voxel: the conservative all-nodes phase runs) and the physical one,
// with both couplings and both methods: settings() are the same after the call.
TEST(MessMinimiser, LeavesTheSystemSettingsAsTheCallerSetThem) {
  for (const char* name : {"seed", "physical"}) {
    const mess::ModelProfile& profile = mess::model_profile(name);
    for (const auto coupling : {mess::MagnetizationCoupling::every_evaluation,
                                mess::MagnetizationCoupling::alternating}) {
      for (const auto method : {mess::MinimiserMethod::lbfgs, mess::MinimiserMethod::fire}) {
        mess::MessSystem sys = two_particles(profile);
        const mess::MessSettings before = sys.settings();
        mess::MinimiserOptions opt;
        opt.method = method;
        opt.coupling = coupling;
        opt.force_tolerance = 1e-5;
        opt.max_iterations = 3000;
        const mess::MinimiserResult r = mess::minimise(sys, opt);
        const std::string where =
            std::string(name) + " " + mess::to_string(method) +
            (coupling == mess::MagnetizationCoupling::alternating ? " alternating"
                                                                  : " every_evaluation");
        // It did relax (the rules were in use), and left the settings alone.
        EXPECT_GT(r.iterations, 0) << where;
        EXPECT_GT(r.magnetization_solves, 0) << where;
        expect_same_settings(sys.settings(), before, where);
      }
    }
  }
}

// An exception thrown while minimise() runs under its own rules (here: an invalid volume force
// factor, rejected by the first evaluation) still leaves the caller's settings.
TEST(MessMinimiser, LeavesTheSystemSettingsWhenAnEvaluationThrows) {
  mess::MessSystem sys = two_particles(mess::model_profile("seed"));
  ASSERT_EQ(sys.settings().centre_rule, mess::CentreRule::centre_voxel);
  sys.settings().elastic.volume_force_factor = -1.0;
  const mess::MessSettings before = sys.settings();
  mess::MinimiserOptions opt;
  opt.coupling = mess::MagnetizationCoupling::alternating;
  EXPECT_THROW((void)mess::minimise(sys, opt), std::invalid_argument);
  expect_same_settings(sys.settings(), before, "after the exception");
}

// The correction passes' forcing term must leave each pass a reduction to make: [0, 1).
TEST(MessMinimiser, RefusesACorrectionForcingOutsideZeroToOne) {
  for (const double forcing : {-0.1, 1.0, 2.0, std::nan("")}) {
    mess::MinimiserOptions opt;
    opt.correction_forcing = forcing;
    try {
      opt.validate();
      ADD_FAILURE() << "accepted correction_forcing = " << forcing;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("correction_forcing must be in [0, 1)"),
                std::string::npos)
          << e.what();
    }
  }
  mess::MinimiserOptions opt;
  opt.correction_forcing = 0.0;  // the exact passes
  EXPECT_NO_THROW(opt.validate());
}
