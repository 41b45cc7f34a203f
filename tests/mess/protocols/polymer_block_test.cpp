// The particle-free block (`[particles] placement = "none"`; docs/run-files-3d.md): the polymer
// reference of the MR effect. A simple shear of it gives the polymer's shear modulus
// G = E / (2 (1 + nu)) (physical profile) and no MR effect, and every 3D run type runs with no
// particles, writing empty particle datasets and the documented NaN / 0 meanings.

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "../../support/hdf5_read.hpp"
#include "../../support/temp_dir.hpp"
#include "../lattice/affine_energy.hpp"
#include "../support/cli_run.hpp"
#include "../support/small_runs.hpp"
#include "mresim/config/config_error.hpp"
#include "mresim/mess/analysis/modulus_fit.hpp"
#include "mresim/mess/lattice/lattice.hpp"

namespace mresim::mess_protocol {
namespace {

using mresim::testing::Hdf5Reader;
using mresim::testing::TempDir;
using testing::run_in;
using testing::spec_of;
using testing::with;

// The example's system (examples/chapter4/small/polymer_block_shear_small.toml).
const std::string kBlock = R"([run]
type = "mess_strain"
[model]
profile = "physical"
youngs_modulus = 9e3
poisson_ratio = 0.47
discretization_order = 1
[particles]
radius = 1.5e-6
placement = "none"
[box]
size = [6e-6, 6e-6, 6e-6]
[field]
magnitudes = [0.0, 0.05, 0.1]
[strain]
kind = "shear"
boundary = "all_faces"
max = 0.02
steps = 4
[output]
checkpoint_every = 0
)";

constexpr double kShearModulus = 9e3 / (2.0 * (1.0 + 0.47));  // G = E / (2 (1 + nu)), Pa

TEST(MessPolymerBlock, ShearGivesThePolymersShearModulusAndNoMrEffect) {
  const TempDir dir;
  const auto r = run_in(dir, kBlock);
  ASSERT_EQ(r.status, 0) << r.err;
  const Hdf5Reader h5(dir / "out" / "results.h5");
  const auto modulus = h5.doubles("/analysis/modulus");
  const auto strain = h5.doubles("/steps/measured_strain");
  const auto field_index = h5.ints("/steps/field_index");
  ASSERT_EQ(modulus.size(), 3U);

  // What the lattice reproduces: with every surface node on the affine simple shear, a
  // particle-free (uniform) lattice relaxes to the affine state itself (each interior node's
  // springs and cells are symmetric), so the energy density at x = tan(gamma) is the affine one,
  // which the test-only evaluator computes exactly from the built lattice's springs and cells.
  // The same least-squares fit of those exact energies is the modulus the run must give.
  const lattice::Lattice lat = lattice::build_lattice(spec_of(kBlock).lattice);
  std::vector<double> x;
  std::vector<double> u;
  for (std::size_t i = 0; i < strain.size(); ++i) {
    if (field_index[i] != 0) continue;
    x.push_back(strain[i]);
    u.push_back(
        lattice::testing::lattice_energy_density(lat, lattice::testing::simple_shear(strain[i])));
  }
  ASSERT_EQ(x.size(), 5U);
  const mess_analysis::QuadraticFit affine = mess_analysis::fit_energy_density(x, u);
  ASSERT_TRUE(affine.valid) << affine.problem;
  // The affine fit is G up to the quartic term of the finite shear (the springs' lengths are
  // exact, not linearised): over x <= 0.02 it raises a by 1.42e-4 G. Bound: 2e-4.
  EXPECT_NEAR(affine.modulus / kShearModulus - 1.0, 0.0, 2e-4);
  EXPECT_GT(affine.modulus, kShearModulus);  // the quartic term stiffens
  for (std::size_t f = 0; f < modulus.size(); ++f) {
    // The relaxed lattice gives the affine energies to the solver's tolerance: the minimiser stops
    // at forces below 1e-6 k_eff l_e, an energy error second order in that (measured: the
    // moduli agree to 1.2e-10 relative). Bound: 1e-7 relative.
    EXPECT_NEAR(modulus[f], affine.modulus, 1e-7 * kShearModulus) << "field " << f;
    EXPECT_NEAR(modulus[f] / kShearModulus - 1.0, 0.0, 2e-4) << "field " << f;
  }
  // No particles: the field acts on nothing, so every field relaxes the same problem and the MR
  // effect is 0 to rounding. (Not bit for bit: the later fields' first strain starts from the
  // previous field's response, solver.load_step_start, the same state up to rounding;
  // measured 9e-14.)
  const auto mr = h5.doubles("/analysis/mr_effect");
  for (std::size_t f = 0; f < mr.size(); ++f) EXPECT_NEAR(mr[f], 0.0, 1e-9) << "field " << f;
  EXPECT_EQ(h5.ints("/analysis/mr_effect_valid"), (std::vector<std::int64_t>{1, 1, 1}));
  EXPECT_EQ(h5.ints("/analysis/valid"), (std::vector<std::int64_t>{1, 1, 1}));
}

// The per-step meanings without particles (docs/outputs-3d.md): empty particle arrays, no pair
// (separation and pair angle NaN), no clusters (count 0, largest 0), M 0, no magnetization
// solve (method "none"), every step valid.
void expect_particle_free_steps(const Hdf5Reader& h5, std::size_t steps) {
  EXPECT_EQ(h5.shape("/steps/centres"), (std::vector<hsize_t>{steps, 0, 3}));
  EXPECT_EQ(h5.shape("/steps/magnetization"), (std::vector<hsize_t>{steps, 0, 3}));
  EXPECT_EQ(h5.shape("/steps/cluster_id"), (std::vector<hsize_t>{steps, 0}));
  EXPECT_EQ(h5.shape("/lattice/initial_centres"), (std::vector<hsize_t>{0, 3}));
  EXPECT_EQ(h5.ints("/steps/valid"), std::vector<std::int64_t>(steps, 1));
  EXPECT_EQ(h5.ints("/steps/cluster_count"), std::vector<std::int64_t>(steps, 0));
  EXPECT_EQ(h5.ints("/steps/largest_cluster"), std::vector<std::int64_t>(steps, 0));
  EXPECT_EQ(h5.ints("/steps/solver/magnetization_solves"), std::vector<std::int64_t>(steps, 0));
  EXPECT_EQ(h5.strings("/steps/solver/magnetization_method"),
            std::vector<std::string>(steps, "none"));
  for (const double s : h5.doubles("/steps/separation")) EXPECT_TRUE(std::isnan(s));
  for (const double a : h5.doubles("/steps/pair_angle")) EXPECT_TRUE(std::isnan(a));
  for (const double m : h5.doubles("/steps/magnetization_projection")) EXPECT_EQ(m, 0.0);
  for (const double e : h5.doubles("/steps/energies/zeeman")) EXPECT_EQ(e, 0.0);
}

TEST(MessPolymerBlock, EveryRunTypeRunsWithoutParticles) {
  const std::string hysteresis =
      with(with(kBlock, "type = \"mess_strain\"", "type = \"mess_hysteresis\""),
           "[strain]\nkind = \"shear\"\nboundary = \"all_faces\"\nmax = 0.02\nsteps = 4\n", "");
  const std::string magnetostriction =
      with(hysteresis, "type = \"mess_hysteresis\"", "type = \"mess_magnetostriction\"");
  const std::string stress =
      with(with(kBlock, "type = \"mess_strain\"", "type = \"mess_stress\""),
           "[strain]\nkind = \"shear\"\nboundary = \"all_faces\"\nmax = 0.02\nsteps = 4\n",
           "[stress]\nkind = \"shear\"\nmax = 20.0\nsteps = 2\n");
  struct Case {
    const char* name;
    std::string toml;
    std::size_t steps;
  };
  for (const Case& c :
       {Case{"mess_strain", kBlock, 15}, Case{"mess_hysteresis", hysteresis, 11},
        Case{"mess_magnetostriction", magnetostriction, 3}, Case{"mess_stress", stress, 9}}) {
    SCOPED_TRACE(c.name);
    const TempDir dir;
    const auto r = run_in(dir, c.toml);
    ASSERT_EQ(r.status, 0) << r.err;
    const Hdf5Reader h5(dir / "out" / "results.h5");
    expect_particle_free_steps(h5, c.steps);
    // No particles, so no magnetostriction: a field strains nothing (only the stress run's
    // traction does, at second order in the shear: its one-face shear bends the block).
    if (std::string(c.name) != "mess_stress") {
      for (const double m : h5.doubles("/steps/magnetostriction")) EXPECT_NEAR(m, 0.0, 1e-12);
    }
  }
}

TEST(MessPolymerBlock, PlacementNoneNeedsABoxAndTakesNoParticleKeys) {
  const mess_config::MessSpec s = spec_of(kBlock);
  EXPECT_EQ(s.placement_kind, lattice::PlacementKind::none);
  EXPECT_EQ(s.geometry.particle_count(), 0U);
  EXPECT_EQ(s.geometry.volume_fraction, 0.0);
  EXPECT_EQ(s.geometry.shape.nodes, (std::array<int, 3>{7, 7, 7}));
  const auto error_of = [](const std::string& toml) -> std::string {
    try {
      (void)spec_of(toml);
    } catch (const config::ConfigError& e) {
      return e.what();
    }
    return "(no error)";
  };
  EXPECT_NE(error_of(with(kBlock, "[box]\nsize = [6e-6, 6e-6, 6e-6]\n", "")).find("[box]"),
            std::string::npos);
  EXPECT_EQ(error_of(with(kBlock, "placement = \"none\"",
                          "placement = \"none\"\npositions = [[3e-6, 3e-6, 3e-6]]")),
            "particles.positions = [[3e-06, 3e-06, 3e-06]]: not used by placement = \"none\" "
            "(only by by_hand)");
}

}  // namespace
}  // namespace mresim::mess_protocol
