#include "mresim/mess/lattice/spheres.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <set>
#include <stdexcept>

namespace mresim::lattice {
namespace {

// Independent count of the voxels: for each (i, j) with i^2 + j^2 <= n^2 + n, the column holds
// 2 floor(sqrt(n^2 + n - i^2 - j^2)) + 1 voxels (voxel centres within R = (n + 1/2) l_e).
int column_count(int n) {
  const int limit = n * n + n;
  int total = 0;
  for (int i = -n; i <= n; ++i) {
    for (int j = -n; j <= n; ++j) {
      const int rest = limit - i * i - j * j;
      if (rest >= 0) total += 2 * static_cast<int>(std::floor(std::sqrt(rest))) + 1;
    }
  }
  return total;
}

// docs/original-code.md#particles: voxels / nodes for n_d = 1, 2, 3, 4, 5, 7.
TEST(LatticeSpheres, VoxelAndNodeCountsOfTheOriginalRasterisation) {
  const int orders[] = {1, 2, 3, 4, 5, 7};
  const int voxels[] = {19, 81, 179, 389, 739, 1791};
  const int nodes[] = {56, 160, 312, 624, 1064, 2368};
  for (int k = 0; k < 6; ++k) {
    EXPECT_EQ(static_cast<int>(sphere_voxel_offsets(orders[k]).size()), voxels[k]);
    EXPECT_EQ(column_count(orders[k]), voxels[k]);
    EXPECT_EQ(static_cast<int>(sphere_node_offsets(orders[k]).size()), nodes[k]);
  }
  EXPECT_THROW(sphere_voxel_offsets(0), std::invalid_argument);
}

TEST(LatticeSpheres, CentredWithDiameterTwoNdPlusOne) {
  const int n = 5;
  const auto v = sphere_voxel_offsets(n);
  std::array<int, 3> lo{0, 0, 0}, hi{0, 0, 0};
  std::array<long, 3> sum{0, 0, 0};
  std::set<std::array<int, 3>> set(v.begin(), v.end());
  for (const auto& o : v) {
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], o[a]);
      hi[a] = std::max(hi[a], o[a]);
      sum[a] += o[a];
    }
    // Symmetric under every reflection and axis permutation.
    EXPECT_TRUE(set.count({-o[0], o[1], o[2]}));
    EXPECT_TRUE(set.count({o[1], o[2], o[0]}));
  }
  for (int a = 0; a < 3; ++a) {
    EXPECT_EQ(hi[a] - lo[a] + 1, 2 * n + 1);
    EXPECT_EQ(sum[a], 0);
  }
  // Voxel volume vs the sphere's: 739 vs 4/3 pi 5.5^3 = 696.9 voxels.
  EXPECT_NEAR(4.0 / 3.0 * std::numbers::pi * std::pow(n + 0.5, 3), 696.9, 0.1);
}

TEST(LatticeSpheres, NodeListStartsWithTheCentreVoxel) {
  const auto nodes = sphere_node_offsets(5);
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (int k = 0; k < 8; ++k) {
    for (int a = 0; a < 3; ++a) {
      EXPECT_GE(nodes[k][a], 0);
      EXPECT_LE(nodes[k][a], 1);
    }
    mean += Eigen::Vector3d(nodes[k][0], nodes[k][1], nodes[k][2]) / 8.0;
  }
  EXPECT_NEAR((mean - Eigen::Vector3d(0.5, 0.5, 0.5)).norm(), 0.0, 1e-15);
  for (std::size_t k = 9; k < nodes.size(); ++k) EXPECT_LT(nodes[k - 1], nodes[k]);
  std::set<std::array<int, 3>> unique(nodes.begin(), nodes.end());
  EXPECT_EQ(unique.size(), nodes.size());
}

TEST(LatticeSpheres, VoxelizeRejectsOverlapAndBoundary) {
  const GridShape shape{{30, 30, 40}};
  const double l_e = 1e-6;
  const ParticleNodes ok = voxelize_particles(shape, {{14, 14, 10}, {14, 14, 22}}, 5, l_e);
  EXPECT_EQ(ok.nodes.size(), 2u);
  EXPECT_EQ(ok.nodes[0].size(), 1064u);
  int marked = 0;
  for (const auto p : ok.particle_of_node) marked += p >= 0;
  EXPECT_EQ(marked, 2 * 1064);
  // 11 voxels apart: the spheres' tips share a node plane.
  EXPECT_THROW(voxelize_particles(shape, {{14, 14, 10}, {14, 14, 21}}, 5, l_e),
               std::invalid_argument);
  try {
    voxelize_particles(shape, {{14, 14, 10}, {14, 14, 21}}, 5, l_e);
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("particles 0 and 1 overlap"), std::string::npos)
        << e.what();
  }
  // Nodes from 5 - 5 = 0: on the outer face.
  EXPECT_THROW(voxelize_particles(shape, {{5, 14, 14}}, 5, l_e), std::invalid_argument);
  EXPECT_NO_THROW(voxelize_particles(shape, {{6, 14, 14}}, 5, l_e));
  EXPECT_THROW(voxelize_particles(shape, {{23, 14, 14}}, 5, l_e), std::invalid_argument);
  EXPECT_NO_THROW(voxelize_particles(shape, {{22, 14, 14}}, 5, l_e));
}

// eqs. 4.53, 4.54: total mass = rho_p (polymer share of the box) + rho_Fe N V_p, where the
// polymer share is the box minus l_e^3 per particle node; that differs from the exact polymer
// volume by the voxelisation: (1064 - 4/3 pi 5.5^3) l_e^3 per particle.
TEST(LatticeSpheres, MassesSumToPolymerPlusIron) {
  const GridShape shape{{30, 30, 40}};
  const double l_e = 3e-6 / 11.0, radius = 1.5e-6;
  const ParticleNodes p = voxelize_particles(shape, {{14, 14, 10}, {14, 14, 25}}, 5, l_e);
  const Eigen::VectorXd m = nodal_masses(shape, l_e, p.nodes, radius);
  const double cell = l_e * l_e * l_e;
  const double box = shape.cell_count() * cell;
  const double vp = 4.0 / 3.0 * std::numbers::pi * radius * radius * radius;
  EXPECT_NEAR(m.sum(), kPolymerDensity * (box - 2 * 1064 * cell) + kIronDensity * 2 * vp,
              1e-12 * m.sum());
  const double exact = kPolymerDensity * (box - 2 * vp) + kIronDensity * 2 * vp;
  EXPECT_NEAR(m.sum(), exact, kPolymerDensity * 2 * (1064 * cell - vp) * (1 + 1e-9));
  EXPECT_LT(std::abs(m.sum() - exact) / exact, 0.02);
  // Interior, face, edge, corner and particle nodes.
  EXPECT_DOUBLE_EQ(m[shape.node_index(3, 3, 3)], kPolymerDensity * cell);
  EXPECT_DOUBLE_EQ(m[shape.node_index(0, 3, 3)], kPolymerDensity * cell / 2);
  EXPECT_DOUBLE_EQ(m[shape.node_index(0, 0, 3)], kPolymerDensity * cell / 4);
  EXPECT_DOUBLE_EQ(m[shape.node_index(0, 0, 0)], kPolymerDensity * cell / 8);
  EXPECT_DOUBLE_EQ(m[p.nodes[0][0]], kIronDensity * vp / 1064);
  EXPECT_NEAR(m[p.nodes[0][0]], 1.044e-16, 0.001e-16);  // docs/original-code.md#particles
  EXPECT_NEAR(m[p.nodes[0][0]] / (kPolymerDensity * cell), 5.34, 0.01);
}

}  // namespace
}  // namespace mresim::lattice
