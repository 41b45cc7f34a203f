#pragma once

// Particle clusters of the 3D model (Section 4.2.8): particles whose centres are closer than a
// contact distance belong to one cluster (connected components of the "in contact" graph).

#include <Eigen/Core>
#include <vector>

namespace mresim::mess_analysis {

struct Clusters {
  std::vector<int> id;  // per particle, 0 .. count-1, numbered by their lowest particle index
  int count = 0;
  int largest = 0;  // particles in the largest cluster
};

// centres: 3 x N_p (m). Particles i, j are in contact when |c_i - c_j| <= contact_distance.
Clusters find_clusters(const Eigen::Matrix3Xd& centres, double contact_distance);

// Smallest centre-to-centre distance (m); 0 for fewer than two particles.
double min_separation(const Eigen::Matrix3Xd& centres);

}  // namespace mresim::mess_analysis
