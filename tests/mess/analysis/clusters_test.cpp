// Tests of the particle cluster analysis of the 3D model (Section 4.2.8): connected components
// of the contact graph, the id numbering, contact at exactly the contact distance, and the
// smallest centre distance.

#include "mresim/mess/analysis/clusters.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace ma = mresim::mess_analysis;

TEST(MessClusters, ChainOfThreeAndOneIsolated) {
  // Particles 0, 2, 3 form a chain along z (0-2 and 2-3 touch, 0-3 do not); 1 is far away.
  const double r = 1.0e-6;
  Eigen::Matrix3Xd c(3, 4);
  c.col(0) << 0.0, 0.0, 0.0;
  c.col(1) << 20e-6, 0.0, 0.0;
  c.col(2) << 0.0, 0.0, 1.9 * r;
  c.col(3) << 0.0, 0.0, 3.8 * r;
  const auto clusters = ma::find_clusters(c, 2.0 * r);
  EXPECT_EQ(clusters.count, 2);
  EXPECT_EQ(clusters.largest, 3);
  EXPECT_EQ(clusters.id, (std::vector<int>{0, 1, 0, 0}));
}

TEST(MessClusters, IdsFollowLowestParticleIndex) {
  // Clusters {0, 3}, {1}, {2, 4}: found from the pairs (2, 4) and (0, 3) in any order, ids
  // still follow the lowest member: 0 -> 0, 1 -> 1, 2 -> 2.
  Eigen::Matrix3Xd c(3, 5);
  c.col(0) << 0.0, 0.0, 0.0;
  c.col(1) << 10.0, 0.0, 0.0;
  c.col(2) << 20.0, 0.0, 0.0;
  c.col(3) << 0.0, 0.0, 1.0;
  c.col(4) << 20.0, 1.0, 0.0;
  const auto clusters = ma::find_clusters(c, 1.5);
  EXPECT_EQ(clusters.count, 3);
  EXPECT_EQ(clusters.largest, 2);
  EXPECT_EQ(clusters.id, (std::vector<int>{0, 1, 2, 0, 2}));
}

TEST(MessClusters, ContactExactlyAtDistanceCounts) {
  Eigen::Matrix3Xd c(3, 2);
  c.col(0) << 0.0, 0.0, 0.0;
  c.col(1) << 3.0, 4.0, 0.0;  // distance exactly 5
  EXPECT_EQ(ma::find_clusters(c, 5.0).count, 1);
  EXPECT_EQ(ma::find_clusters(c, std::nextafter(5.0, 0.0)).count, 2);

  c.col(1) << 2e-6, 0.0, 0.0;
  const auto touching = ma::find_clusters(c, 2e-6);
  EXPECT_EQ(touching.count, 1);
  EXPECT_EQ(touching.largest, 2);
}

TEST(MessClusters, EmptyAndSingle) {
  const auto none = ma::find_clusters(Eigen::Matrix3Xd(3, 0), 1.0);
  EXPECT_EQ(none.count, 0);
  EXPECT_EQ(none.largest, 0);
  EXPECT_TRUE(none.id.empty());
  const auto one = ma::find_clusters(Eigen::Matrix3Xd::Zero(3, 1), 1.0);
  EXPECT_EQ(one.count, 1);
  EXPECT_EQ(one.largest, 1);
  EXPECT_EQ(one.id, (std::vector<int>{0}));
}

TEST(MessClusters, MinSeparation) {
  Eigen::Matrix3Xd c(3, 3);
  c.col(0) << 0.0, 0.0, 0.0;
  c.col(1) << 0.0, 6e-6, 8e-6;  // 10 um from 0
  c.col(2) << 0.0, 6e-6, 3e-6;  // 5 um from 1
  EXPECT_NEAR(ma::min_separation(c), 5e-6, 1e-18);
  EXPECT_EQ(ma::min_separation(Eigen::Matrix3Xd(3, 0)), 0.0);
  EXPECT_EQ(ma::min_separation(Eigen::Matrix3Xd::Ones(3, 1)), 0.0);
}
