// Every 3D protocol through the ProtocolRunner on the small two-particle system
// (small_runs.hpp): magnetostriction, tension, compression, torsion, stress-controlled tension
// and shear, and the dissertation's leapfrog as the relaxation method of a seed-profile run.

#include <gtest/gtest.h>

#include <cmath>

#include "../support/small_runs.hpp"
#include "mresim/mess/analysis/modulus_fit.hpp"
#include "mresim/mess/lattice/grid.hpp"
#include "mresim/mess/lattice/stiffness.hpp"
#include "mresim/mess/protocols/protocol_runner.hpp"

namespace mresim::mess_protocol {
namespace {

using testing::spec_of;

struct ProtocolRun {
  ProtocolState state;
  double youngs_modulus = 0.0;
  double shear_modulus = 0.0;      // the polymer's, of the profile
  std::vector<double> top_face_z;  // mean z of the top face per step
};

ProtocolRun run(const std::string& toml) {
  const mess_config::MessSpec spec = spec_of(toml);
  ProtocolRunner runner(spec);
  ProtocolRun r;
  r.state = runner.initial_state();
  const lattice::Lattice& lat = runner.system().lattice();
  const std::vector<int> top = lattice::face_nodes(lat.shape, lattice::Face::top);
  runner.run(r.state, [&](const ProtocolState&) {
    double z = 0.0;
    for (const int n : top) z += runner.system().positions()(2, n);
    r.top_face_z.push_back(z / static_cast<double>(top.size()));
  });
  r.youngs_modulus = spec.lattice.youngs_modulus;
  r.shear_modulus = lattice::target_shear_modulus(
      spec.lattice.shear_modulus_rule, spec.lattice.youngs_modulus, spec.lattice.poisson_ratio);
  for (const StepRecord& s : r.state.records) {
    EXPECT_TRUE(s.converged) << "step " << s.step.index << ": " << s.status;
  }
  return r;
}

// The run file of type `type` for the small model, followed by `tables`.
std::string small_run_file(const char* type, const std::string& tables) {
  return std::string("[run]\ntype = \"") + type + "\"\n" + testing::kSmallModel + tables;
}

// Modulus from energy density against measured strain at field index 0.
double fitted_modulus(const ProtocolState& state) {
  std::vector<double> x;
  std::vector<double> u;
  for (const StepRecord& s : state.records) {
    if (s.step.field_index != 0) continue;
    x.push_back(s.measured_strain);
    u.push_back(s.energies.total() / s.system_volume);
  }
  const mess_analysis::QuadraticFit fit = mess_analysis::fit_energy_density(x, u);
  EXPECT_TRUE(fit.valid);
  return fit.modulus;
}

TEST(MessProtocolKinds, MagnetostrictionHoldsOnlyTheBottomAndThePairContracts) {
  const ProtocolRun r =
      run(small_run_file("mess_magnetostriction", "\n[field]\nmagnitudes = [0.0, 0.1]\n"));
  ASSERT_EQ(r.state.records.size(), 2U);
  const double lz = 17e-6;  // 18 nodes at l_e = 1 um
  EXPECT_NEAR(r.top_face_z[0], lz, 1e-15);
  // The attracting pair pulls the free top face down: the block shortens along the field.
  EXPECT_LT(r.top_face_z[1], lz - 1e-10);
  const StepRecord& s = r.state.records[1];
  EXPECT_LT((s.centres.col(1) - s.centres.col(0)).norm(), 7e-6);
}

TEST(MessProtocolKinds, TensionAndCompressionGiveAnEffectiveYoungsModulus) {
  for (const char* kind : {"tension", "compression"}) {
    const ProtocolRun r =
        run(small_run_file("mess_strain", std::string("\n[field]\nmagnitudes = [0.0]\n"
                                                      "\n[strain]\nkind = \"") +
                                              kind + "\"\nmax = 0.01\nsteps = 2\n"));
    ASSERT_EQ(r.state.records.size(), 3U);
    const double e_eff = fitted_modulus(r.state);
    // Clamped faces stiffen a short block (docs/mess-solvers.md: 1.195 E for a particle-free
    // 5 x 6 x 7 block) and the particles add to it.
    EXPECT_GT(e_eff, r.youngs_modulus) << kind;
    EXPECT_LT(e_eff, 2.0 * r.youngs_modulus) << kind;
    const double sign = std::string(kind) == "tension" ? 1.0 : -1.0;
    EXPECT_NEAR(r.top_face_z[2], 17e-6 * (1.0 + sign * 0.01), 1e-15) << kind;
  }
}

TEST(MessProtocolKinds, TorsionStoresEnergyQuadraticInTheTwist) {
  const ProtocolRun r =
      run(small_run_file("mess_strain",
                         "\n[field]\nmagnitudes = [0.0]\n"
                         "\n[strain]\nkind = \"torsion\"\nmax = 2.0\nsteps = 2\n"));
  ASSERT_EQ(r.state.records.size(), 3U);
  const double e1 = r.state.records[1].energies.total();
  const double e2 = r.state.records[2].energies.total();
  EXPECT_GT(e1, 0.0);
  EXPECT_NEAR(e2 / e1, 4.0, 0.05);  // small twists: E ~ twist^2
  EXPECT_NEAR(r.state.records[2].measured_strain, 2.0 * std::numbers::pi / 180.0, 1e-12);
}

TEST(MessProtocolKinds, StressControlledTensionAndShearMeasureTheirStrain) {
  const ProtocolRun tension =
      run(small_run_file("mess_stress",
                         "\n[field]\nmagnitudes = [0.0]\n"
                         "\n[stress]\nkind = \"tension\"\nmax = 100.0\nsteps = 2\n"));
  ASSERT_EQ(tension.state.records.size(), 3U);
  const double eps = tension.state.records[2].measured_strain;
  EXPECT_GT(eps, 0.0);
  // Lower face held, upper face pulled and free to contract: stress / strain near E.
  EXPECT_NEAR(100.0 / eps, tension.youngs_modulus, 0.3 * tension.youngs_modulus);
  EXPECT_NEAR(tension.state.records[1].measured_strain, 0.5 * eps, 0.01 * eps);  // linear

  const ProtocolRun shear =
      run(small_run_file("mess_stress",
                         "\n[field]\nmagnitudes = [0.0]\n"
                         "\n[stress]\nkind = \"shear\"\nmax = 20.0\nsteps = 1\n"));
  ASSERT_EQ(shear.state.records.size(), 2U);
  // A short block held at the bottom and pushed at the top also bends (docs/mess-solvers.md:
  // 0.29 G for a particle-free block): the apparent modulus is below G but positive.
  const double gamma = shear.state.records[1].measured_strain;
  EXPECT_GT(gamma, 0.0);
  EXPECT_LT(20.0 / gamma, shear.shear_modulus);
}

// The seed profile relaxed by the dissertation's damped leapfrog reaches the state the
// minimiser finds.
TEST(MessProtocolKinds, LeapfrogRunMatchesTheMinimiser) {
  const std::string base = "[run]\ntype = \"mess_hysteresis\"\n" +
                           std::string(testing::kSmallModel) +
                           "\n[field]\nmagnitudes = [0.05]\nsequence = \"up\"\n";
  std::string seed = base;
  seed.replace(seed.find("profile = \"physical\""), 20, "profile = \"seed\"");
  const ProtocolRun minimiser = run(seed);
  const ProtocolRun leapfrog = run(seed +
                                   "\n[solver]\nmethod = \"leapfrog\"\n"
                                   "\n[solver.leapfrog]\ndt = 3e-3\nsteps_per_round = 2000\n");
  ASSERT_EQ(leapfrog.state.records.size(), 1U);
  const StepRecord& a = minimiser.state.records[0];
  const StepRecord& b = leapfrog.state.records[0];
  const double sa = (a.centres.col(1) - a.centres.col(0)).norm();
  const double sb = (b.centres.col(1) - b.centres.col(0)).norm();
  EXPECT_LT(sa, 7e-6 - 1e-8);  // the pair moved
  EXPECT_NEAR(sb, sa, 1e-3 * (7e-6 - sa));
  EXPECT_NEAR(b.energies.total(), a.energies.total(), 1e-3 * std::abs(a.energies.total()));
  EXPECT_EQ(b.status, "converged");
  // What finished each step is recorded: the seed's forces took correction passes in L-BFGS.
  EXPECT_EQ(b.finished_by, "leapfrog");
  EXPECT_EQ(a.finished_by, "lbfgs");
  EXPECT_GE(a.correction_passes, 1);
  EXPECT_EQ(b.correction_passes, 0);
}

// The name of what finished a step follows the fallbacks: FIRE over the slope-only search over
// the configured method.
TEST(MessProtocolKinds, FinishedByNamesTheLastMethodThatRan) {
  mess::MinimiserResult r;
  EXPECT_EQ(finished_by_name(r, false), "lbfgs");
  EXPECT_EQ(finished_by_name(r, true), "newton");
  r.finished_with_lbfgs = true;  // Newton's line search failed
  EXPECT_EQ(finished_by_name(r, true), "lbfgs");
  r.slope_only_fallback = true;
  EXPECT_EQ(finished_by_name(r, true), "lbfgs_slope_only");
  EXPECT_EQ(finished_by_name(r, false), "lbfgs_slope_only");
  r.finished_with_fire = true;
  EXPECT_EQ(finished_by_name(r, false), "fire");
  EXPECT_EQ(finished_by_name(r, true), "fire");
}

// solver.method = "newton" follows the same states along a loop as the default L-BFGS, with
// one multigrid for all steps: centres to 1 nm, energies to 1e-6 relative.
TEST(MessProtocolKinds, NewtonRunFollowsTheLbfgsLoop) {
  const std::string base = testing::small_hysteresis(0.05, 2);
  const ProtocolRun lbfgs = run(base);
  const ProtocolRun newton = run(base + "\n[solver]\nmethod = \"newton\"\n");
  ASSERT_EQ(newton.state.records.size(), lbfgs.state.records.size());
  ASSERT_EQ(newton.state.records.size(), 11U);  // 0 -> max -> -max -> max
  for (std::size_t k = 0; k < lbfgs.state.records.size(); ++k) {
    const StepRecord& a = lbfgs.state.records[k];
    const StepRecord& b = newton.state.records[k];
    EXPECT_EQ(b.status, "converged") << k;
    EXPECT_LT((a.centres - b.centres).cwiseAbs().maxCoeff(), 1e-9) << k;
    EXPECT_NEAR(b.energies.total(), a.energies.total(), 1e-6 * std::abs(a.energies.total()) + 1e-22)
        << k;
    EXPECT_EQ(a.krylov_iterations, 0) << k;  // L-BFGS does no CG
    EXPECT_EQ(a.finished_by, "lbfgs") << k;
    EXPECT_EQ(b.finished_by, "newton") << k;
    if (k > 0 && a.iterations == 0) {
      // Where the loop turns, the field secant starts from the result at the same field on the
      // way up: apart, that is already the equilibrium for either method.
      EXPECT_EQ(b.iterations, 0) << k;
    } else if (k > 0) {
      EXPECT_LT(b.iterations, a.iterations) << k;  // Newton steps against L-BFGS steps
      // Newton's directions come from CG (recorded per step).
      if (b.iterations > 0) EXPECT_GT(b.krylov_iterations, 0) << k;
    }
  }
}

}  // namespace
}  // namespace mresim::mess_protocol
