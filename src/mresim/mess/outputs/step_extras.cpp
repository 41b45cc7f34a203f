#include "mresim/mess/outputs/step_extras.hpp"

#include <limits>

#include "mresim/mess/analysis/box_strain.hpp"
#include "mresim/mess/analysis/clusters.hpp"
#include "mresim/mess/analysis/pair_orientation.hpp"

namespace mresim::mess_protocol {

namespace ma = mresim::mess_analysis;

StepExtras step_extras(const std::vector<StepRecord>& records, const Eigen::Vector3d& d,
                       double cluster_distance, double ms) {
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  StepExtras x;
  for (const StepRecord& r : records) {
    x.field_projection.push_back(r.step.field.dot(d));
    const auto np = r.magnetization.cols();
    x.magnetization_projection.push_back(np > 0 ? (d.transpose() * r.magnetization).mean() / ms
                                                : 0.0);
    x.energy_density.push_back(r.energies.total() / r.system_volume);
    x.magnetostriction.push_back(ma::strain_along(r.box_strain, d));
    if (!r.centres.allFinite()) {  // no distances: NaN separation, cluster data -1
      x.separation.push_back(kNaN);
      x.pair_angle.push_back(kNaN);
      x.cluster_count.push_back(-1);
      x.largest_cluster.push_back(-1);
      x.cluster_id.insert(x.cluster_id.end(), static_cast<std::size_t>(np), -1);
      continue;
    }
    // Fewer than two particles: no pair, so no separation and no angle (NaN); no particles: no
    // clusters (count 0, largest 0).
    x.separation.push_back(np >= 2 ? ma::min_separation(r.centres) : kNaN);
    x.pair_angle.push_back(ma::pair_angle(r.centres, d));
    const ma::Clusters c = ma::find_clusters(r.centres, cluster_distance);
    x.cluster_count.push_back(c.count);
    x.largest_cluster.push_back(c.largest);
    x.cluster_id.insert(x.cluster_id.end(), c.id.begin(), c.id.end());
  }
  return x;
}

}  // namespace mresim::mess_protocol
