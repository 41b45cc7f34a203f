#include "mresim/mess/lattice/volume_elements.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <random>

namespace mresim::lattice {
namespace {

CellVertices unit_cube(double l) {
  CellVertices x;
  for (int v = 0; v < 8; ++v) {
    const auto o = vertex_offset(v);
    x[v] = l * Eigen::Vector3d(o[0], o[1], o[2]);
  }
  return x;
}

TEST(LatticeVolumeElements, VertexOrderOfTheOriginal) {
  // bit 0 = +z, bit 1 = +x, bit 2 = +y.
  EXPECT_EQ(vertex_offset(1), (std::array<int, 3>{0, 0, 1}));
  EXPECT_EQ(vertex_offset(2), (std::array<int, 3>{1, 0, 0}));
  EXPECT_EQ(vertex_offset(4), (std::array<int, 3>{0, 1, 0}));
  EXPECT_EQ(vertex_offset(7), (std::array<int, 3>{1, 1, 1}));
  const GridShape shape{{3, 4, 5}};
  const auto elements = build_elements(shape);
  ASSERT_EQ(static_cast<std::int64_t>(elements.size()), shape.cell_count());
  // Cell 1 is the next along x: its v0 is node (1, 0, 0).
  EXPECT_EQ(elements[1][0], shape.node_index(1, 0, 0));
  EXPECT_EQ(elements[shape.cell_index(1, 2, 3)][0], shape.node_index(1, 2, 3));
  EXPECT_EQ(elements[shape.cell_index(1, 2, 3)][5], shape.node_index(1, 3, 4));
  EXPECT_EQ(elements[shape.cell_index(1, 2, 3)][6], shape.node_index(2, 3, 3));
}

// The cells computed from the grid are the stored array's, cell by cell, through indexing,
// iteration and cell_at(corner), on boxes with 2 nodes along an axis and on uneven ones.
TEST(LatticeVolumeElements, GridCellsAreTheStoredCells) {
  for (const GridShape shape :
       {GridShape{{2, 2, 2}}, GridShape{{3, 4, 5}}, GridShape{{7, 2, 3}}, GridShape{{4, 6, 2}}}) {
    const auto stored = build_elements(shape);
    const GridCells cells(shape);
    ASSERT_EQ(cells.size(), stored.size());
    std::size_t c = 0;
    for (const auto& cell : cells) {
      ASSERT_LT(c, stored.size());
      EXPECT_EQ(cell, stored[c]) << "cell " << c;
      EXPECT_EQ(cells[c], stored[c]) << "cell " << c;
      EXPECT_EQ(cells.corner(static_cast<std::int64_t>(c)), stored[c][0]) << "cell " << c;
      EXPECT_EQ(cells.cell_at(stored[c][0]), stored[c]) << "cell " << c;
      ++c;
    }
    EXPECT_EQ(c, stored.size());
  }
  EXPECT_TRUE(GridCells().empty());
}

TEST(LatticeVolumeElements, VolumeOfUndeformedAndAffineCells) {
  const double l = 0.3;
  EXPECT_NEAR(cell_volume(unit_cube(l)), l * l * l, 1e-15);
  const EdgeVectors e = averaged_edge_vectors(unit_cube(l));
  EXPECT_NEAR((e.a - Eigen::Vector3d(l, 0, 0)).norm(), 0.0, 1e-15);
  EXPECT_NEAR((e.b - Eigen::Vector3d(0, l, 0)).norm(), 0.0, 1e-15);
  EXPECT_NEAR((e.c - Eigen::Vector3d(0, 0, l)).norm(), 0.0, 1e-15);
  // Homogeneous deformation: exact (eq. 4.48).
  Eigen::Matrix3d f;
  f << 1.1, 0.2, -0.05, 0.03, 0.9, 0.1, -0.2, 0.07, 1.3;
  CellVertices x = unit_cube(l);
  for (auto& v : x) v = f * v + Eigen::Vector3d(0.4, -1.0, 2.0);
  EXPECT_NEAR(cell_volume(x), f.determinant() * l * l * l, 1e-14);
}

TEST(LatticeVolumeElements, GradientMatchesFiniteDifferences) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-0.2, 0.2);
  for (int trial = 0; trial < 20; ++trial) {
    CellVertices x = unit_cube(1.0);
    for (auto& v : x) v += Eigen::Vector3d(u(rng), u(rng), u(rng));
    CellVertices g;
    const double v0 = cell_volume_and_gradient(x, g);
    EXPECT_NEAR(v0, cell_volume(x), 1e-15);
    const double h = 1e-6;
    for (int v = 0; v < 8; ++v) {
      for (int d = 0; d < 3; ++d) {
        CellVertices xp = x, xm = x;
        xp[v][d] += h;
        xm[v][d] -= h;
        const double fd = (cell_volume(xp) - cell_volume(xm)) / (2 * h);
        EXPECT_NEAR(g[v][d], fd, 1e-9) << "vertex " << v << " component " << d;
      }
    }
    // Translations do not change V: the gradients sum to zero.
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (const auto& gv : g) sum += gv;
    EXPECT_NEAR(sum.norm(), 0.0, 1e-14);
  }
  // Undeformed cell of edge l: |dV/dx_v| = sqrt(3) l^2 / 4 along the outward diagonal.
  CellVertices g;
  cell_volume_and_gradient(unit_cube(2.0), g);
  EXPECT_NEAR((g[7] - Eigen::Vector3d(1, 1, 1)).norm(), 0.0, 1e-15);
  EXPECT_NEAR((g[0] + Eigen::Vector3d(1, 1, 1)).norm(), 0.0, 1e-15);
}

}  // namespace
}  // namespace mresim::lattice
