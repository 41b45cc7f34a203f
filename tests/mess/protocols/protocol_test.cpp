// The 3D protocols on small systems (seconds): the hysteresis protocol's physics (attraction
// along the field, symmetry, magnetization following the loop), simple shear's G_eff at zero
// field and its rise with the field (issue requirement), and that a run resumed from a
// checkpoint reproduces the uninterrupted run bit for bit.

#include <gtest/gtest.h>

#include <cmath>

#include "../../support/temp_dir.hpp"
#include "../support/checkpoint_round_trip.hpp"
#include "../support/small_runs.hpp"
#include "mresim/mess/analysis/modulus_fit.hpp"
#include "mresim/mess/lattice/stiffness.hpp"
#include "mresim/mess/outputs/checkpoint.hpp"
#include "mresim/mess/protocols/protocol_runner.hpp"
#include "mresim/mess/protocols/step_plan.hpp"

namespace mresim::mess_protocol {
namespace {

using testing::small_hysteresis;
using testing::spec_of;

double separation(const StepRecord& r) { return (r.centres.col(1) - r.centres.col(0)).norm(); }

TEST(MessProtocolHysteresis, ParticlesAttractAlongTheFieldAndKeepTheSymmetry) {
  const mess_config::MessSpec spec = spec_of(small_hysteresis(0.2, 2));
  ProtocolRunner runner(spec);
  ProtocolState state = runner.initial_state();
  runner.run(state, nullptr);
  ASSERT_EQ(state.records.size(), 11U);  // 5 n + 1 for n = 2 increments

  const double s0 = separation(state.records[0]);
  EXPECT_NEAR(s0, 7e-6, 1e-12);  // zero field: nothing moves
  const double box_x = 4.5e-6;
  for (const StepRecord& r : state.records) {
    EXPECT_TRUE(r.converged) << "step " << r.step.index << ": " << r.status;
    // The box and the pair are symmetric about the box's vertical axis.
    for (int p = 0; p < 2; ++p) {
      EXPECT_NEAR(r.centres(0, p), box_x, 1e-10);
      EXPECT_NEAR(r.centres(1, p), box_x, 1e-10);
    }
  }
  // Field along the pair: attraction, larger at the larger field; symmetric in +-B.
  const StepRecord& max_up = state.records[2];    // +0.2 T
  const StepRecord& max_down = state.records[6];  // -0.2 T
  EXPECT_LT(separation(state.records[1]), s0);
  EXPECT_LT(separation(max_up), separation(state.records[1]));
  EXPECT_NEAR(separation(max_down), separation(max_up), 1e-6 * s0);
  // Magnetization follows the field's sign; at 0.2 T well below saturation.
  EXPECT_GT(max_up.magnetization(2, 0), 0.0);
  EXPECT_LT(max_down.magnetization(2, 0), 0.0);
  EXPECT_LT(max_up.magnetization.col(0).norm(), spec.particles.Ms);
  // The system's energy falls with the field (Zeeman and dipole terms are negative).
  EXPECT_LT(max_up.energies.total(), 0.0);
}

TEST(MessProtocolHysteresis, ResumedFromACheckpointEqualsTheUninterruptedRun) {
  const std::string toml = small_hysteresis(0.2, 2);
  const mess_config::MessSpec spec = spec_of(toml);

  ProtocolRunner uninterrupted(spec);
  ProtocolState full = uninterrupted.initial_state();
  uninterrupted.run(full, nullptr);

  const mresim::testing::TempDir dir;
  const auto checkpoint = dir / "checkpoint.h5";
  ProtocolRunner second(spec);  // a new process would start like this
  ProtocolState resumed = testing::resumed_after(toml, 4, checkpoint, second);
  ASSERT_EQ(resumed.next_step, 4U);
  second.run(resumed, nullptr);

  ASSERT_EQ(resumed.records.size(), full.records.size());
  for (std::size_t i = 0; i < full.records.size(); ++i) {
    const StepRecord& a = full.records[i];
    const StepRecord& b = resumed.records[i];
    EXPECT_EQ(a.energies.total(), b.energies.total()) << "step " << i;
    EXPECT_EQ(a.energies["springs"], b.energies["springs"]) << "step " << i;
    EXPECT_EQ(a.centres, b.centres) << "step " << i;
    EXPECT_EQ(a.magnetization, b.magnetization) << "step " << i;
    EXPECT_EQ(a.iterations, b.iterations) << "step " << i;
  }
  EXPECT_THROW(read_checkpoint(checkpoint, second, toml + "\n# edited\n"), std::runtime_error);
}

// Simple shear perpendicular to a pair aligned with the field: the particles stiffen the
// elastomer (G_eff(0) above the polymer's G) and the field stiffens it further, because
// shearing tilts the pair away from the field (Section 4.3, Fig. 4.18). At 0.1 T (+30 %); at
// 0.15 T this coarse pair (n_d = 1, 3 l_e of polymer between the particles) is past the
// sideways-buckling instability of the squeezed gap and G_eff from the fit drops instead.
TEST(MessProtocolShear, EffectiveModulusExceedsThePolymersAndRisesWithTheField) {
  const std::string toml = std::string("[run]\ntype = \"mess_strain\"\n") + testing::kSmallModel +
                           "\n[field]\nmagnitudes = [0.0, 0.1]\n"
                           "\n[strain]\nkind = \"shear\"\nnormal = \"z\"\ndirection = \"x\"\n"
                           "max = 0.02\nsteps = 2\n";
  const mess_config::MessSpec spec = spec_of(toml);
  ProtocolRunner runner(spec);
  ProtocolState state = runner.initial_state();
  runner.run(state, nullptr);
  ASSERT_EQ(state.records.size(), 6U);

  std::vector<double> moduli;
  for (std::size_t f = 0; f < 2; ++f) {
    std::vector<double> x;
    std::vector<double> u;
    for (const StepRecord& r : state.records) {
      if (r.step.field_index != f) continue;
      EXPECT_TRUE(r.converged) << "step " << r.step.index;
      x.push_back(r.measured_strain);
      u.push_back(r.energies.total() / r.system_volume);
    }
    const mess_analysis::QuadraticFit fit = mess_analysis::fit_energy_density(x, u);
    ASSERT_TRUE(fit.valid);
    moduli.push_back(fit.modulus);
  }
  const double g_polymer = lattice::target_shear_modulus(
      spec.lattice.shear_modulus_rule, spec.lattice.youngs_modulus, spec.lattice.poisson_ratio);
  EXPECT_GT(moduli[0], g_polymer);
  EXPECT_LT(moduli[0], 1.5 * g_polymer);  // Phi = 2 %: a small stiffening
  EXPECT_GT(moduli[1], moduli[0]);
}

}  // namespace
}  // namespace mresim::mess_protocol
