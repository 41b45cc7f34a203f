#pragma once

// The settings of a 3D system (MessSystem) that its energy terms may read too: the elastic
// terms' volume force factor, where a particle's magnetic centre is, how the magnetizations
// are kept up to date. Each model profile has its settings: ModelProfile::system_settings().

#include "mresim/mess/magnetization/self_consistent.hpp"
#include "mresim/mess/terms/elastic_terms.hpp"

namespace mresim::mess {

// Where a particle's magnetic centre is.
enum class CentreRule {
  all_nodes,     // mean of all its nodes: spreading the force evenly is the exact gradient
  centre_voxel,  // mean of the 8 corners of its centre voxel (the original code)
};

enum class MagnetizationUpdate {
  every_evaluation,  // re-solve before every energy/gradient evaluation (the original)
  on_displacement,   // re-solve when a centre moved more than resolve_distance since the last
  manual,            // only in solve_magnetization()
};

struct MessSettings {
  ElasticTermSettings elastic;
  CentreRule centre_rule = CentreRule::all_nodes;
  magnetism::MagnetizationOptions magnetization;  // demagnetization follows the model's flag
  MagnetizationUpdate magnetization_update = MagnetizationUpdate::every_evaluation;
  double resolve_distance = 1e-3;  // in units of l_e (on_displacement)
};

}  // namespace mresim::mess
