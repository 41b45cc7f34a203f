#pragma once

// What the outputs derive per step from a step's record (docs/outputs-3d.md, /steps): the field
// and magnetization along the field direction, the energy density, the smallest separation and
// the closest pair's angle to the field, the clusters, and the magnetostriction (the box strain
// along the field).

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "mresim/mess/protocols/protocol_runner.hpp"

namespace mresim::mess_protocol {

struct StepExtras {
  std::vector<double> field_projection;          // T
  std::vector<double> magnetization_projection;  // 1 (units of Ms); 0 without particles
  std::vector<double> energy_density;            // J/m^3
  std::vector<double> separation;             // m; NaN with fewer than 2 particles or NaN centres
  std::vector<double> pair_angle;             // rad; NaN as separation
  std::vector<double> magnetostriction;       // 1
  std::vector<std::int64_t> cluster_count;    // -1 where the centres are not finite
  std::vector<std::int64_t> largest_cluster;  // -1 likewise; 0 without particles
  std::vector<std::int64_t> cluster_id;       // steps x particles
};

// d: the run's field direction (unit); cluster_distance: contact at centres this close (m);
// ms: the saturation magnetization (A/m).
StepExtras step_extras(const std::vector<StepRecord>& records, const Eigen::Vector3d& d,
                       double cluster_distance, double ms);

}  // namespace mresim::mess_protocol
