// The model-profile table: every row of the two profiles, the lookup by name and its error,
// and that the rules reach the lattice, the system and the leapfrog unchanged.

#include "mresim/mess/profile/model_profile.hpp"

#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

namespace mresim::mess {
namespace {

TEST(ModelProfile, NamesInTableOrderPhysicalFirst) {
  EXPECT_EQ(model_profile_names(), (std::vector<std::string>{"physical", "seed"}));
  EXPECT_EQ(model_profile("physical").name, "physical");
  EXPECT_EQ(model_profile("seed").name, "seed");
}

TEST(ModelProfile, UnknownNameIsRefusedNamingTheAllowedOnes) {
  try {
    (void)model_profile("Seed");
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "unknown model profile 'Seed': allowed values are physical, seed");
  }
}

// The physical profile: the dissertation's text with exact gradients.
TEST(ModelProfile, PhysicalRows) {
  const ModelProfile& p = model_profile("physical");
  EXPECT_EQ(p.shear_modulus_rule, lattice::ShearModulusRule::from_youngs_and_poisson);
  EXPECT_EQ(p.particle_spring_rule, lattice::ParticleSpringRule::same_particle);
  EXPECT_EQ(p.default_box_rounding, lattice::BoxRounding::nearest);
  EXPECT_EQ(p.poisson_ratio_lower_limit, -1.0);
  EXPECT_EQ(p.volume_force_factor, 1.0);
  EXPECT_EQ(p.centre_rule, CentreRule::all_nodes);
  EXPECT_FALSE(p.wca_ms.has_value());
  EXPECT_EQ(p.wca_scale_ms(1.6e6), 1.6e6);
  EXPECT_EQ(p.leapfrog_rigid_group_rule, RigidGroupRule::total_force);
  EXPECT_FALSE(p.leapfrog_stability_tabulated);
}

// The seed profile: the original code's choices.
TEST(ModelProfile, SeedRows) {
  const ModelProfile& s = model_profile("seed");
  EXPECT_EQ(s.shear_modulus_rule, lattice::ShearModulusRule::two_fifths_youngs);
  EXPECT_EQ(s.particle_spring_rule, lattice::ParticleSpringRule::any_particle);
  EXPECT_EQ(s.default_box_rounding, lattice::BoxRounding::seed_floor_divide);
  EXPECT_DOUBLE_EQ(s.poisson_ratio_lower_limit, lattice::seed_bulk_stability_limit());
  EXPECT_NEAR(s.poisson_ratio_lower_limit, -0.1124, 1e-4);
  EXPECT_EQ(s.volume_force_factor, 4.0);
  EXPECT_EQ(s.centre_rule, CentreRule::centre_voxel);
  ASSERT_TRUE(s.wca_ms.has_value());
  EXPECT_EQ(s.wca_scale_ms(1.6e6), 1.9e6);  // whatever the run's Ms
  EXPECT_EQ(s.leapfrog_rigid_group_rule, RigidGroupRule::mean_acceleration);
  EXPECT_TRUE(s.leapfrog_stability_tabulated);
}

// What apply_to, system_settings and leapfrog_options pass down is the table's rows and
// nothing else (every other setting at the defaults of its struct).
TEST(ModelProfile, RulesReachTheLatticeSystemAndLeapfrog) {
  for (const std::string& name : model_profile_names()) {
    SCOPED_TRACE(name);
    const ModelProfile& p = model_profile(name);
    lattice::LatticeSpec spec;
    p.apply_to(spec);
    EXPECT_EQ(spec.shear_modulus_rule, p.shear_modulus_rule);
    EXPECT_EQ(spec.particle_spring_rule, p.particle_spring_rule);
    EXPECT_EQ(spec.youngs_modulus, lattice::LatticeSpec{}.youngs_modulus);

    const MessSettings settings = p.system_settings();
    EXPECT_EQ(settings.elastic.volume_force_factor, p.volume_force_factor);
    EXPECT_EQ(settings.centre_rule, p.centre_rule);
    EXPECT_EQ(settings.magnetization_update, MessSettings{}.magnetization_update);

    const LeapfrogOptions leapfrog = p.leapfrog_options();
    EXPECT_EQ(leapfrog.rigid_group_rule, p.leapfrog_rigid_group_rule);
    EXPECT_EQ(leapfrog.time_step, LeapfrogOptions{}.time_step);
  }
}

}  // namespace
}  // namespace mresim::mess
