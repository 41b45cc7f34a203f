#include "mresim/mess/analysis/clusters.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

namespace mresim::mess_analysis {

namespace {

// Union-find root with path halving. Particle counts are small (up to ~100), so the O(N^2)
// pair loop below dominates anyway.
int root(std::vector<int>& parent, int i) {
  while (parent[static_cast<std::size_t>(i)] != i) {
    auto& p = parent[static_cast<std::size_t>(i)];
    p = parent[static_cast<std::size_t>(p)];
    i = p;
  }
  return i;
}

}  // namespace

Clusters find_clusters(const Eigen::Matrix3Xd& centres, double contact_distance) {
  const int n = static_cast<int>(centres.cols());
  std::vector<int> parent(static_cast<std::size_t>(n));
  std::iota(parent.begin(), parent.end(), 0);
  // The distance itself (not its square) is compared, exactly as documented, so a pair at
  // exactly the contact distance counts as touching.
  for (int i = 0; i < n; ++i) {
    for (int j = i + 1; j < n; ++j) {
      if ((centres.col(i) - centres.col(j)).norm() <= contact_distance) {
        // Keep the lower index as root so the root of each cluster is its lowest particle.
        const int a = root(parent, i);
        const int b = root(parent, j);
        if (a != b) parent[static_cast<std::size_t>(std::max(a, b))] = std::min(a, b);
      }
    }
  }

  // Ids in the order the clusters' lowest particles appear (Section 4.2.8 counts clusters;
  // a stable numbering keeps per-step cluster ids comparable in output files).
  Clusters result;
  result.id.assign(static_cast<std::size_t>(n), -1);
  std::vector<int> id_of_root(static_cast<std::size_t>(n), -1);
  std::vector<int> sizes;
  for (int i = 0; i < n; ++i) {
    const int r = root(parent, i);
    auto& id = id_of_root[static_cast<std::size_t>(r)];
    if (id < 0) {
      id = result.count++;
      sizes.push_back(0);
    }
    result.id[static_cast<std::size_t>(i)] = id;
    ++sizes[static_cast<std::size_t>(id)];
  }
  result.largest = sizes.empty() ? 0 : *std::max_element(sizes.begin(), sizes.end());
  return result;
}

double min_separation(const Eigen::Matrix3Xd& centres) {
  const Eigen::Index n = centres.cols();
  if (n < 2) return 0.0;
  double best = std::numeric_limits<double>::infinity();
  for (Eigen::Index i = 0; i < n; ++i) {
    for (Eigen::Index j = i + 1; j < n; ++j) {
      best = std::min(best, (centres.col(i) - centres.col(j)).squaredNorm());
    }
  }
  return std::sqrt(best);
}

}  // namespace mresim::mess_analysis
