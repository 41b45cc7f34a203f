#pragma once

// The model profiles of the 3D model: everything that `[model] profile = "physical"` or
// `"seed"` changes, in one table (model_profile.cpp). The run file names a profile once
// (run_file/read_mess_spec.cpp); the table's entry is then passed down as plain rules, and no
// other code compares profile names. docs/model-profiles.md explains every row.
//
//   physical  the model as the dissertation's text states it, with exact gradients: a
//             particle-free lattice has the user's E and nu (G = E/(2(1+nu))), the volume
//             forces are the gradient of the reported volume energy, the magnetic force is
//             spread over all of a particle's nodes, whose mean is its centre.
//   seed      the choices of the original MESS code, to reproduce its published numbers:
//             G = 2E/5 whatever nu (eq. 4.14 as eqs. 4.42-4.44 use it), volume forces 4x the
//             gradient of the reported energy, particle springs between nodes of any two
//             particles, the centre voxel's 8 corners as the centre, WCA scaled with
//             Ms = 1.9e6 A/m whatever the run's Ms, floor-divided box sizes, and the leapfrog's
//             rigid groups moved with the mean acceleration.

#include <optional>
#include <string_view>
#include <vector>

#include "mresim/mess/lattice/lattice.hpp"
#include "mresim/mess/solvers/leapfrog.hpp"
#include "mresim/mess/system/system_energy.hpp"

namespace mresim::mess {

struct ModelProfile {
  std::string_view name;  // as in the run file
  // ---- lattice (Sections 4.2.1-4.2.2)
  lattice::ShearModulusRule shear_modulus_rule;
  std::string_view shear_modulus_note;  // what `mresim info` says about G
  lattice::ParticleSpringRule particle_spring_rule;
  lattice::BoxRounding default_box_rounding;  // [box] rounding when the run file is silent
  // The lattice is stable only for nu above this (exclusive); -1 means any nu > -1.
  double poisson_ratio_lower_limit;
  std::string_view poisson_ratio_limit_reason;  // why, for the run file's error message
  // ---- energy terms (Section 4.2.4)
  double volume_force_factor;  // volume forces / exact volume gradient (elastic_terms.hpp)
  CentreRule centre_rule;      // where a particle's magnetic centre is
  // The Ms that scales the WCA energy E_max = mu0 pi Ms^2 R^3/72; empty: the run's Ms.
  std::optional<double> wca_ms;
  // ---- solvers
  RigidGroupRule leapfrog_rigid_group_rule;
  // The leapfrog's stability limit dt < 2/omega_max is tabulated for this profile's lattices
  // (solvers/leapfrog.hpp leapfrog_stability_limit), so the run file reader checks dt.
  bool leapfrog_stability_tabulated;

  // The Ms that scales WCA for a run with saturation magnetization run_ms.
  double wca_scale_ms(double run_ms) const { return wca_ms.value_or(run_ms); }
  // Writes the profile's lattice rules into spec.
  void apply_to(lattice::LatticeSpec& spec) const;
  // The system settings of this profile (magnetization options left at their defaults).
  MessSettings system_settings() const;
  // The leapfrog options of this profile (everything else at its default).
  LeapfrogOptions leapfrog_options() const;
};

// The entry named `name`; throws std::invalid_argument naming the allowed names otherwise.
const ModelProfile& model_profile(std::string_view name);
// The names of all profiles, in table order ("physical" first: the default).
std::vector<std::string> model_profile_names();

}  // namespace mresim::mess
