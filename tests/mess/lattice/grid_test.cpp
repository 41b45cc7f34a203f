#include "mresim/mess/lattice/grid.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <stdexcept>

#include "../../support/dissertation_values.hpp"

namespace mresim::lattice {
namespace {

using mresim::testing::kR;

TEST(LatticeGrid, ElementLengthIsEquation449) {
  EXPECT_DOUBLE_EQ(element_length(kR, 5), 3e-6 / 11.0);
  EXPECT_NEAR(element_length(kR, 5), 0.2727e-6, 0.0001e-6);
  EXPECT_DOUBLE_EQ(element_length(kR, 2), 3e-6 / 5.0);
  EXPECT_THROW(element_length(kR, 0), std::invalid_argument);
  EXPECT_THROW(element_length(-1.0, 5), std::invalid_argument);
}

TEST(LatticeGrid, NodeAndCellNumbering) {
  const GridShape s{{4, 5, 6}};
  EXPECT_EQ(s.node_count(), 120);
  EXPECT_EQ(s.cell_count(), 60);
  // z fastest, then x, then y.
  EXPECT_EQ(s.node_index(0, 0, 1), 1);
  EXPECT_EQ(s.node_index(1, 0, 0), 6);
  EXPECT_EQ(s.node_index(0, 1, 0), 24);
  // cells: x fastest, then y, then z.
  EXPECT_EQ(s.cell_index(1, 0, 0), 1);
  EXPECT_EQ(s.cell_index(0, 1, 0), 3);
  EXPECT_EQ(s.cell_index(0, 0, 1), 12);
  for (int n = 0; n < s.node_count(); ++n) {
    const auto c = s.node_coordinates(n);
    EXPECT_EQ(s.node_index(c[0], c[1], c[2]), n);
  }
  for (int n = 0; n < s.cell_count(); ++n) {
    const auto c = s.cell_coordinates(n);
    EXPECT_EQ(s.cell_index(c[0], c[1], c[2]), n);
  }
}

TEST(LatticeGrid, NodeTypeCodes) {
  using namespace node_type;
  const GridShape s{{4, 5, 6}};
  const int X = 3, Y = 4, Z = 5;
  EXPECT_EQ(node_type_code(s, 1, 1, 1), kInterior);
  EXPECT_EQ(node_type_code(s, 0, 1, 1), kLeft);
  EXPECT_EQ(node_type_code(s, X, 1, 1), kRight);
  EXPECT_EQ(node_type_code(s, 1, 1, Z), kTop);
  EXPECT_EQ(node_type_code(s, 1, 1, 0), kBottom);
  EXPECT_EQ(node_type_code(s, 1, 0, 1), kFront);
  EXPECT_EQ(node_type_code(s, 1, Y, 1), kBack);
  EXPECT_EQ(node_type_code(s, 0, 1, Z), kLeftTop);
  EXPECT_EQ(node_type_code(s, 0, 1, 0), kLeftBottom);
  EXPECT_EQ(node_type_code(s, 0, 0, 1), kLeftFront);
  EXPECT_EQ(node_type_code(s, 0, Y, 1), kLeftBack);
  EXPECT_EQ(node_type_code(s, X, 1, Z), kRightTop);
  EXPECT_EQ(node_type_code(s, X, 1, 0), kRightBottom);
  EXPECT_EQ(node_type_code(s, X, 0, 1), kRightFront);
  EXPECT_EQ(node_type_code(s, X, Y, 1), kRightBack);
  EXPECT_EQ(node_type_code(s, 1, 0, Z), kTopFront);
  EXPECT_EQ(node_type_code(s, 1, Y, Z), kTopBack);
  EXPECT_EQ(node_type_code(s, 1, 0, 0), kBottomFront);
  EXPECT_EQ(node_type_code(s, 1, Y, 0), kBottomBack);
  EXPECT_EQ(node_type_code(s, 0, 0, 0), 19);
  EXPECT_EQ(node_type_code(s, X, 0, 0), 20);
  EXPECT_EQ(node_type_code(s, 0, Y, 0), 21);
  EXPECT_EQ(node_type_code(s, 0, 0, Z), 22);
  EXPECT_EQ(node_type_code(s, X, Y, 0), 23);
  EXPECT_EQ(node_type_code(s, X, 0, Z), 24);
  EXPECT_EQ(node_type_code(s, 0, Y, Z), 25);
  EXPECT_EQ(node_type_code(s, X, Y, Z), 26);
  // Counts per class: interior (N-2)^3, faces, edges, 8 corners.
  const auto codes = node_type_codes(s);
  int counts[5] = {0, 0, 0, 0, 0};
  for (const auto c : codes) ++counts[static_cast<int>(node_class(c))];
  EXPECT_EQ(counts[static_cast<int>(NodeClass::interior)], 2 * 3 * 4);
  EXPECT_EQ(counts[static_cast<int>(NodeClass::face)], 2 * (3 * 4 + 2 * 4 + 2 * 3));
  EXPECT_EQ(counts[static_cast<int>(NodeClass::edge)], 4 * (2 + 3 + 4));
  EXPECT_EQ(counts[static_cast<int>(NodeClass::corner)], 8);
  EXPECT_EQ(node_class(node_type::kParticle), NodeClass::particle);
}

TEST(LatticeGrid, FaceNodes) {
  const GridShape s{{4, 5, 6}};
  EXPECT_EQ(face_nodes(s, Face::left).size(), 30u);
  EXPECT_EQ(face_nodes(s, Face::top).size(), 20u);
  EXPECT_EQ(face_nodes(s, Face::back).size(), 24u);
  for (const int n : face_nodes(s, Face::right)) EXPECT_EQ(s.node_coordinates(n)[0], 3);
  for (const int n : face_nodes(s, Face::bottom)) EXPECT_EQ(s.node_coordinates(n)[2], 0);
}

// Python's round (ties to even), float floor division and round(x, 1) -> int.
TEST(LatticeGrid, PythonRoundingRules) {
  EXPECT_EQ(nodes_along_axis(1.5, 1.0), 2);  // round(2.5) = 2
  EXPECT_EQ(nodes_along_axis(2.5, 1.0), 4);  // round(3.5) = 4
  const double l_e = element_length(kR, 5);
  EXPECT_EQ(12e-6 / l_e, 44.0);                      // plain division rounds to exactly 44
  EXPECT_EQ(python_floor_divide(12e-6, l_e), 43.0);  // ... but Python's // gives 43
  EXPECT_EQ(python_floor_divide(18e-6, l_e), 65.0);
  EXPECT_EQ(python_floor_divide(40e-6, l_e), 146.0);
  EXPECT_EQ(python_floor_divide(62e-6, l_e), 227.0);
  EXPECT_EQ(python_floor_divide(7.0, 2.0), 3.0);
  EXPECT_EQ(python_floor_divide(-7.0, 2.0), -4.0);
  EXPECT_EQ(seed_spacing_voxels(28.546), 28);
  EXPECT_EQ(seed_spacing_voxels(25.926), 25);  // round(25.926, 1) = 25.9
  EXPECT_EQ(seed_spacing_voxels(25.96), 26);   // round(25.96, 1) = 26.0
  // Beyond int's range is an error, not a wrapped (undefined) conversion; found by UBSan.
  EXPECT_THROW((void)seed_spacing_voxels(1.4e108), std::invalid_argument);
  EXPECT_THROW((void)seed_spacing_voxels(std::nan("")), std::invalid_argument);
}

struct D1Case {
  double volume_fraction;
  std::array<int, 3> nodes;
  std::int64_t node_count;
  std::int64_t cell_count;
  int spacing_voxels;
};

// Claim D1: node and cell counts of the regular two-particle systems ([1, 1, 2] along z,
// R = 1.5 um, n_d = 5). Spacings: the original's rule (28, 25, 22 voxels for 3, 4, 6 %, i.e.
// 7.636, 6.818, 6.000 um; the dissertation's stated S for those equal the box width).
TEST(LatticeGrid, DissertationCountsFromVolumeFraction) {
  const double l_e = element_length(kR, 5);
  const D1Case cases[] = {
      {0.01, {42, 42, 83}, 146412, 137842, 41}, {0.03, {30, 30, 58}, 52200, 47937, 28},
      {0.04, {27, 27, 53}, 38637, 35152, 25},   {0.05, {25, 25, 49}, 30625, 27648, 24},
      {0.06, {24, 24, 46}, 26496, 23805, 22},   {0.07, {23, 23, 44}, 23276, 20812, 21},
  };
  for (const auto& c : cases) {
    const VolumeFractionBox box = box_from_volume_fraction(kR, l_e, c.volume_fraction, {1, 1, 2});
    EXPECT_EQ(box.shape.nodes, c.nodes) << c.volume_fraction;
    EXPECT_EQ(box.shape.node_count(), c.node_count) << c.volume_fraction;
    EXPECT_EQ(box.shape.cell_count(), c.cell_count) << c.volume_fraction;
    EXPECT_EQ(box.spacing_voxels[2], c.spacing_voxels) << c.volume_fraction;
  }
  // Stated separations that do follow the rule: 11.1818, 6.5454, 5.7272 um (1, 5, 7 %).
  EXPECT_NEAR(41 * l_e, 11.1818e-6, 1e-10);
  EXPECT_NEAR(24 * l_e, 6.5454e-6, 1e-10);
  EXPECT_NEAR(21 * l_e, 5.7272e-6, 1e-10);
  EXPECT_NEAR(28 * l_e, 7.636e-6, 1e-9);
  EXPECT_NEAR(25 * l_e, 6.818e-6, 1e-9);
  EXPECT_NEAR(22 * l_e, 6.000e-6, 1e-9);
}

TEST(LatticeGrid, FirstCentreSitsOnACellCentre) {
  const double l_e = element_length(kR, 5);
  // Phi = 1 %: 41 x 41 x 82 cells, S = 41: centres at 20.5 (x, y) and 20.5, 61.5 (z).
  const VolumeFractionBox box = box_from_volume_fraction(kR, l_e, 0.01, {1, 1, 2});
  EXPECT_EQ(box.first_centre[0], 20.5);
  EXPECT_EQ(box.first_centre[2], 20.5);
  // Phi = 5 %: 24 cells, even excess -> 12 + 1/2.
  const VolumeFractionBox b5 = box_from_volume_fraction(kR, l_e, 0.05, {1, 1, 2});
  EXPECT_EQ(b5.first_centre[0], 12.5);
  EXPECT_EQ(b5.first_centre[2], 12.5);
  // Anisotropic: L_a = n_a s f_a, S_a = int(S f_a).
  const double f = 2.0;
  const VolumeFractionBox an = box_from_volume_fraction(
      kR, l_e, 0.01, {2, 2, 2}, {1.0 / std::sqrt(f), 1.0 / std::sqrt(f), f});
  EXPECT_EQ(an.spacing_voxels[0], static_cast<int>(41 / std::sqrt(2.0)));
  EXPECT_EQ(an.spacing_voxels[2], 82);
  EXPECT_EQ(an.shape.nodes[2], nodes_along_axis(2 * an.cube_side * f, l_e));
}

TEST(LatticeGrid, InvalidSizes) {
  const double l_e = element_length(kR, 5);
  EXPECT_THROW(box_from_volume_fraction(kR, l_e, 0.0, {1, 1, 2}), std::invalid_argument);
  EXPECT_THROW(box_from_volume_fraction(kR, l_e, 1.2, {1, 1, 2}), std::invalid_argument);
  EXPECT_THROW(box_from_volume_fraction(kR, l_e, 0.01, {0, 1, 2}), std::invalid_argument);
  EXPECT_THROW(box_from_volume_fraction(kR, l_e, 0.01, {1, 1, 2}, {1, -1, 1}),
               std::invalid_argument);
  EXPECT_THROW(validate_grid_shape(GridShape{{1, 4, 4}}), std::invalid_argument);
  EXPECT_THROW(validate_grid_shape(GridShape{{2000, 2000, 2000}}), std::invalid_argument);
}

}  // namespace
}  // namespace mresim::lattice
