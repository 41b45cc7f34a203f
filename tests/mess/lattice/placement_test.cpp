#include "mresim/mess/lattice/placement.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "../../support/dissertation_values.hpp"

namespace mresim::lattice {
namespace {

using mresim::testing::kR;

// l_e at n_d = 5, as element_length gives it.
const double kElementLength = element_length(kR, 5);

double separation_um(const PlacedParticles& p, std::size_t i, std::size_t j) {
  double d2 = 0.0;
  for (int a = 0; a < 3; ++a) {
    const double d = p.centre_cells[i][a] - p.centre_cells[j][a];
    d2 += d * d;
  }
  return std::sqrt(d2) * kElementLength * 1e6;
}

std::string error_of(const Placement& placement) {
  try {
    place_particles(placement, kR, 5);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

TEST(LatticePlacement, KindNamesAndAliases) {
  EXPECT_EQ(parse_placement_kind("regular"), PlacementKind::regular);
  EXPECT_EQ(parse_placement_kind("regular_noisy"), PlacementKind::regular_noisy);
  EXPECT_EQ(parse_placement_kind("regular_anisotropic"), PlacementKind::regular_anisotropic);
  EXPECT_EQ(parse_placement_kind("anisotropic_regular"), PlacementKind::regular_anisotropic);
  EXPECT_EQ(parse_placement_kind("anisotropic_regular_noisy"),
            PlacementKind::regular_anisotropic_noisy);
  EXPECT_EQ(parse_placement_kind("by_hand"), PlacementKind::by_hand);
  EXPECT_EQ(parse_placement_kind("helix"), PlacementKind::helix);
  EXPECT_THROW(parse_placement_kind("random"), std::invalid_argument);
  RegularPlacement r;
  r.anisotropic = r.noisy = true;
  EXPECT_EQ(kind_of(r), PlacementKind::regular_anisotropic_noisy);
  EXPECT_EQ(to_string(kind_of(HelixPlacement{})), "helix");
  // "none": a by-hand placement without positions, the particle-free block.
  EXPECT_EQ(parse_placement_kind("none"), PlacementKind::none);
  EXPECT_EQ(to_string(PlacementKind::none), "none");
  EXPECT_EQ(kind_of(ByHandPlacement{}), PlacementKind::none);
  ByHandPlacement one;
  one.positions.emplace_back(1e-6, 1e-6, 1e-6);
  EXPECT_EQ(kind_of(one), PlacementKind::by_hand);
}

TEST(LatticePlacement, NoParticlesGiveThePolymerBlock) {
  ByHandPlacement none;
  none.box.lengths = Eigen::Vector3d(6e-6, 5e-6, 4e-6);
  const PlacedParticles p = place_particles(none, kR, 1);  // l_e = 1 um
  EXPECT_TRUE(p.centre_cells.empty());
  EXPECT_EQ(p.shape.nodes, (std::array<int, 3>{7, 6, 5}));
}

// Phi = 1 % and 5 %: the dissertation's separations (11.1818, 6.5454 um), centred in x and y.
TEST(LatticePlacement, RegularTwoParticleSystems) {
  const PlacedParticles p1 = place_particles(RegularPlacement{0.01, {1, 1, 2}}, kR, 5);
  ASSERT_EQ(p1.centre_cells.size(), 2u);
  EXPECT_EQ(p1.centre_cells[0], (std::array<int, 3>{20, 20, 20}));
  EXPECT_EQ(p1.centre_cells[1], (std::array<int, 3>{20, 20, 61}));
  EXPECT_NEAR(separation_um(p1, 0, 1), 11.1818, 1e-4);
  EXPECT_NEAR(separation_um(place_particles(RegularPlacement{0.05, {1, 1, 2}}, kR, 5), 0, 1),
              6.5454, 1e-4);
  // Phi = 3, 4, 6 %: the original's rule gives 7.636, 6.818, 6.000 um.
  EXPECT_NEAR(separation_um(place_particles(RegularPlacement{0.03, {1, 1, 2}}, kR, 5), 0, 1),
              7.6364, 1e-4);
  EXPECT_NEAR(separation_um(place_particles(RegularPlacement{0.04, {1, 1, 2}}, kR, 5), 0, 1),
              6.8182, 1e-4);
  EXPECT_NEAR(separation_um(place_particles(RegularPlacement{0.06, {1, 1, 2}}, kR, 5), 0, 1), 6.0,
              1e-9);
  EXPECT_NEAR(separation_um(place_particles(RegularPlacement{0.07, {1, 1, 2}}, kR, 5), 0, 1),
              5.7273, 1e-4);
  // Order: x outer, y, z inner.
  const PlacedParticles p8 = place_particles(RegularPlacement{0.01, {2, 2, 2}}, kR, 5);
  ASSERT_EQ(p8.centre_cells.size(), 8u);
  EXPECT_EQ(p8.centre_cells[1][2] - p8.centre_cells[0][2], 41);
  EXPECT_EQ(p8.centre_cells[2][1] - p8.centre_cells[0][1], 41);
  EXPECT_EQ(p8.centre_cells[4][0] - p8.centre_cells[0][0], 41);
}

TEST(LatticePlacement, AnisotropicAndNoisy) {
  RegularPlacement r{0.02, {2, 2, 2}};
  r.anisotropic = true;
  const double f = 1.5;
  r.anisotropy_factor = {1 / std::sqrt(f), 1 / std::sqrt(f), f};
  const PlacedParticles a = place_particles(r, kR, 5);
  const VolumeFractionBox box =
      box_from_volume_fraction(kR, kElementLength, 0.02, {2, 2, 2}, r.anisotropy_factor);
  EXPECT_EQ(a.shape.nodes, box.shape.nodes);
  EXPECT_EQ(a.centre_cells[1][2] - a.centre_cells[0][2], box.spacing_voxels[2]);
  EXPECT_EQ(a.centre_cells[4][0] - a.centre_cells[0][0], box.spacing_voxels[0]);
  EXPECT_GT(box.spacing_voxels[2], box.spacing_voxels[0]);

  r.noisy = true;
  r.noise_seed = 12345;
  const PlacedParticles n1 = place_particles(r, kR, 5);
  const PlacedParticles n2 = place_particles(r, kR, 5);
  EXPECT_EQ(n1.centre_cells, n2.centre_cells);  // reproducible
  int moved = 0;
  for (std::size_t p = 0; p < 8; ++p) {
    for (int ax = 0; ax < 3; ++ax) {
      const int d = n1.centre_cells[p][ax] - a.centre_cells[p][ax];
      EXPECT_GE(d, -1);
      EXPECT_LE(d, 1);
      moved += d != 0;
    }
  }
  EXPECT_GT(moved, 0);
  r.noise_seed = 999;
  EXPECT_NE(place_particles(r, kR, 5).centre_cells, n1.centre_cells);
  // All of -1, 0, +1 occur and nothing else, over many seeds.
  RegularPlacement iso{0.01, {1, 1, 2}};
  iso.noisy = true;
  int seen[3] = {0, 0, 0};
  const PlacedParticles base = place_particles(RegularPlacement{0.01, {1, 1, 2}}, kR, 5);
  for (std::uint64_t seed = 0; seed < 50; ++seed) {
    iso.noise_seed = seed;
    const PlacedParticles q = place_particles(iso, kR, 5);
    for (int ax = 0; ax < 3; ++ax) ++seen[q.centre_cells[0][ax] - base.centre_cells[0][ax] + 1];
  }
  EXPECT_GT(seen[0], 20);
  EXPECT_GT(seen[1], 20);
  EXPECT_GT(seen[2], 20);
}

// Figs. 4.10-4.13, 4.20: by-hand boxes of 12 x 12 x 40 um take the original's floor division:
// 44 x 44 x 147 nodes, 269,954 cells, reported Phi = 0.516 % for two particles.
TEST(LatticePlacement, ChainsInTheLargeBox) {
  ChainPlacement c;
  c.box = {Eigen::Vector3d(12e-6, 12e-6, 40e-6), BoxRounding::seed_floor_divide};
  c.count = 2;
  c.separation = 24 * kElementLength;  // 6.5454 um
  const PlacedParticles two = place_particles(c, kR, 5);
  EXPECT_EQ(two.shape.nodes, (std::array<int, 3>{44, 44, 147}));
  EXPECT_EQ(two.shape.node_count(), 284592);
  EXPECT_EQ(two.shape.cell_count(), 269954);
  EXPECT_NEAR(separation_um(two, 0, 1), 6.5454, 1e-4);
  const double phi = 2 * sphere_volume(kR) / (43.0 * 43.0 * 146.0 * std::pow(kElementLength, 3));
  EXPECT_NEAR(phi, 0.00516, 0.000005);
  c.separation = 20 * kElementLength;  // 5.4545 um (Fig. 4.13)
  EXPECT_NEAR(separation_um(place_particles(c, kR, 5), 0, 1), 5.4545, 1e-4);
  // Four-particle chain, S = 6 um (Fig. 4.20): Phi ~ 1 %.
  c.count = 4;
  c.separation = 6e-6;
  const PlacedParticles four = place_particles(c, kR, 5);
  ASSERT_EQ(four.centre_cells.size(), 4u);
  for (std::size_t i = 1; i < 4; ++i) EXPECT_NEAR(separation_um(four, i - 1, i), 6.0, 1e-9);
  EXPECT_NEAR(4 * sphere_volume(kR) / (43.0 * 43.0 * 146.0 * std::pow(kElementLength, 3)), 0.0103,
              0.0001);
  // With nearest rounding the same box has 45 x 45 x 148 nodes (12 um = 44 l_e exactly).
  c.box.rounding = BoxRounding::nearest;
  EXPECT_EQ(place_particles(c, kR, 5).shape.nodes, (std::array<int, 3>{45, 45, 148}));
}

// Section 4.3.3 / Appendix A Listing A.2: 8 particles, R_helix = 0.5 .. 3.5 um, S_z = 5 um,
// dphi = pi/4, box 18 x 18 x 62 um: 66 x 66 x 228 nodes, 959,075 cells.
TEST(LatticePlacement, Helix) {
  HelixPlacement h;
  h.box = {Eigen::Vector3d(18e-6, 18e-6, 62e-6), BoxRounding::seed_floor_divide};
  h.radius = 3.5e-6;
  const auto x = helix_positions(h);
  ASSERT_EQ(x.size(), 8u);
  EXPECT_NEAR(x[0][0], 12.5e-6, 1e-18);  // 9 + 3.5 um
  EXPECT_NEAR(x[0][1], 9e-6, 1e-18);
  EXPECT_NEAR(x[0][2], 13.5e-6, 1e-18);  // Appendix A: 13.5 um + i 5 um
  EXPECT_NEAR(x[7][2], 48.5e-6, 1e-18);
  EXPECT_NEAR(x[2][0], 9e-6, 1e-18);
  EXPECT_NEAR(x[2][1], 12.5e-6, 1e-18);
  const PlacedParticles p = place_particles(h, kR, 5);
  EXPECT_EQ(p.shape.nodes, (std::array<int, 3>{66, 66, 228}));
  EXPECT_EQ(p.shape.node_count(), 993168);
  EXPECT_EQ(p.shape.cell_count(), 959075);
  // Snapped by floor(x/l_e) + 1/2.
  EXPECT_EQ(p.centre_cells[0][2], static_cast<int>(std::floor(13.5e-6 / kElementLength)));
  for (const double r : {0.5e-6, 1.5e-6, 2.5e-6}) {
    h.radius = r;
    EXPECT_NO_THROW(place_particles(h, kR, 5));
  }
  // The dissertation's "Phi ~ 2 %" does not follow from this box: 8 V_p / V = 0.58 %.
  EXPECT_NEAR(8 * sphere_volume(kR) / (959075 * std::pow(kElementLength, 3)), 0.0058, 0.0001);
}

TEST(LatticePlacement, ByHandSnapsToTheContainingCell) {
  ByHandPlacement b;
  b.box = {Eigen::Vector3d(10e-6, 10e-6, 10e-6), BoxRounding::nearest};
  b.positions = {Eigen::Vector3d(5e-6, 5e-6, 2.9e-6), Eigen::Vector3d(5.1e-6, 4.9e-6, 7e-6)};
  const PlacedParticles p = place_particles(b, kR, 5);
  for (std::size_t i = 0; i < 2; ++i) {
    for (int a = 0; a < 3; ++a) {
      EXPECT_EQ(p.centre_cells[i][a],
                static_cast<int>(std::floor(b.positions[i][a] / kElementLength)));
    }
  }
  EXPECT_EQ(place_particles(ByHandPlacement{b.box, {}}, kR, 5).centre_cells.size(), 0u);
}

TEST(LatticePlacement, ErrorsNameTheProblem) {
  ByHandPlacement b;
  b.box = {Eigen::Vector3d(10e-6, 10e-6, 12e-6), BoxRounding::nearest};
  // Overlap: 2 um apart.
  b.positions = {Eigen::Vector3d(5e-6, 5e-6, 4e-6), Eigen::Vector3d(5e-6, 5e-6, 6e-6)};
  std::string e = error_of(b);
  EXPECT_NE(e.find("overlap"), std::string::npos) << e;
  EXPECT_NE(e.find("particles 0 and 1"), std::string::npos) << e;
  // Just far enough: 12 voxels (one polymer voxel between the tips).
  b.positions = {Eigen::Vector3d(5e-6, 5e-6, 11.5 * kElementLength),
                 Eigen::Vector3d(5e-6, 5e-6, 23.5 * kElementLength)};
  EXPECT_EQ(error_of(b), "");
  // Outside the box.
  b.positions = {Eigen::Vector3d(5e-6, 5e-6, 13e-6)};
  e = error_of(b);
  EXPECT_NE(e.find("outside the box"), std::string::npos) << e;
  EXPECT_NE(e.find("particle 0"), std::string::npos) << e;
  b.positions = {Eigen::Vector3d(-1e-6, 5e-6, 5e-6)};
  EXPECT_NE(error_of(b).find("outside the box"), std::string::npos);
  // Inside, but the sphere reaches the boundary.
  b.positions = {Eigen::Vector3d(1e-6, 5e-6, 5e-6)};
  e = error_of(b);
  EXPECT_NE(e.find("touches its outer faces"), std::string::npos) << e;
  // Noisy regular placement can push particles together or onto the boundary: at a spacing
  // of 13 voxels (one-voxel polymer margin to the faces), two along z, some seeds throw.
  RegularPlacement r{0.0, {1, 1, 2}};
  r.volume_fraction = sphere_volume(kR) / std::pow(13.2 * kElementLength, 3);
  EXPECT_EQ(
      box_from_volume_fraction(kR, kElementLength, r.volume_fraction, {1, 1, 2}).spacing_voxels[2],
      13);
  EXPECT_EQ(error_of(r), "");
  r.noisy = true;
  int overlaps = 0;
  for (std::uint64_t seed = 0; seed < 30; ++seed) {
    r.noise_seed = seed;
    const std::string msg = error_of(r);
    if (!msg.empty()) {
      ++overlaps;
      EXPECT_TRUE(msg.find("overlap") != std::string::npos ||
                  msg.find("outer faces") != std::string::npos)
          << msg;
    }
  }
  EXPECT_GT(overlaps, 0);
  // Invalid parameters.
  ChainPlacement c;
  c.box = b.box;
  c.separation = -1.0;
  EXPECT_NE(error_of(c).find("separation"), std::string::npos);
  c.separation = 5e-6;
  c.axis = 3;
  EXPECT_NE(error_of(c).find("axis"), std::string::npos);
  ByHandPlacement empty_box;
  EXPECT_NE(error_of(empty_box).find("box lengths"), std::string::npos);
}

}  // namespace
}  // namespace mresim::lattice
