#include "mresim/mess/profile/model_profile.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <array>
#include <stdexcept>
#include <string>

namespace mresim::mess {

namespace {

// The table. Every difference between the profiles is one field here (docs/model-profiles.md).
const std::array<ModelProfile, 2>& profiles() {
  static const std::array<ModelProfile, 2> table{{
      {.name = "physical",
       .shear_modulus_rule = lattice::ShearModulusRule::from_youngs_and_poisson,
       .shear_modulus_note = "G = E/(2(1+nu)): the lattice has the given E and nu",
       .particle_spring_rule = lattice::ParticleSpringRule::same_particle,
       .default_box_rounding = lattice::BoxRounding::nearest,
       .poisson_ratio_lower_limit = -1.0,
       .poisson_ratio_limit_reason = "the bulk modulus E/(3(1-2nu)) must be positive",
       .volume_force_factor = 1.0,
       .centre_rule = CentreRule::all_nodes,
       .wca_ms = std::nullopt,
       .leapfrog_rigid_group_rule = RigidGroupRule::total_force,
       .leapfrog_stability_tabulated = false},
      {.name = "seed",
       .shear_modulus_rule = lattice::ShearModulusRule::two_fifths_youngs,
       .shear_modulus_note = "G = 2E/5 whatever nu (eqs. 4.42-4.44 as the original evaluates them)",
       .particle_spring_rule = lattice::ParticleSpringRule::any_particle,
       .default_box_rounding = lattice::BoxRounding::seed_floor_divide,
       .poisson_ratio_lower_limit = lattice::seed_bulk_stability_limit(),
       .poisson_ratio_limit_reason =
           "below it the seed lattice's bulk modulus kappa + 2E/3 is not positive (unstable)",
       .volume_force_factor = 4.0,
       .centre_rule = CentreRule::centre_voxel,
       .wca_ms = 1.9e6,  // A/m, hard-coded in the original whatever the run's Ms
       .leapfrog_rigid_group_rule = RigidGroupRule::mean_acceleration,
       .leapfrog_stability_tabulated = true},
  }};
  return table;
}

}  // namespace

void ModelProfile::apply_to(lattice::LatticeSpec& spec) const {
  spec.shear_modulus_rule = shear_modulus_rule;
  spec.particle_spring_rule = particle_spring_rule;
}

MessSettings ModelProfile::system_settings() const {
  MessSettings s;
  s.elastic.volume_force_factor = volume_force_factor;
  s.centre_rule = centre_rule;
  return s;
}

LeapfrogOptions ModelProfile::leapfrog_options() const {
  LeapfrogOptions o;
  o.rigid_group_rule = leapfrog_rigid_group_rule;
  return o;
}

const ModelProfile& model_profile(std::string_view name) {
  for (const ModelProfile& p : profiles()) {
    if (p.name == name) return p;
  }
  throw std::invalid_argument(fmt::format("unknown model profile '{}': allowed values are {}", name,
                                          fmt::join(model_profile_names(), ", ")));
}

std::vector<std::string> model_profile_names() {
  std::vector<std::string> names;
  for (const ModelProfile& p : profiles()) names.emplace_back(p.name);
  return names;
}

}  // namespace mresim::mess
