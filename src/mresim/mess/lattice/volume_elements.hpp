#pragma once

// Volume elements (cells) of the lattice: geometry only (Section 4.2.2, eqs. 4.45-4.48).
//
// Local vertex order of the original code (docs/original-code.md#volume-elements; the
// dissertation's 1-based labels in eqs. 4.45-4.47 differ and eq. 4.46 is garbled): vertex v has
// offset (dx, dy, dz) = ((v >> 1) & 1, (v >> 2) & 1, v & 1), i.e. bit 0 = +z, bit 1 = +x, bit 2 =
// +y:
//   v0 (x,y,z)  v1 (x,y,z+1)  v2 (x+1,y,z)  v3 (x+1,y,z+1)
//   v4 (x,y+1,z)  v5 (x,y+1,z+1)  v6 (x+1,y+1,z)  v7 (x+1,y+1,z+1).
// Averaged edge vectors:
//   a = (v2 - v0 + v3 - v1 + v6 - v4 + v7 - v5)/4   (+x edges, eq. 4.45)
//   b = (v4 - v0 + v6 - v2 + v5 - v1 + v7 - v3)/4   (+y edges, eq. 4.46)
//   c = (v1 - v0 + v3 - v2 + v5 - v4 + v7 - v6)/4   (+z edges, eq. 4.47)
// and V = a . (b x c) (eq. 4.48), exact for a homogeneously deformed cell.

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "mresim/mess/lattice/grid.hpp"

namespace mresim::lattice {

// Offset of local vertex v (0..7) from the cell's lower corner, in cells.
inline std::array<int, 3> vertex_offset(int v) { return {(v >> 1) & 1, (v >> 2) & 1, v & 1}; }

// The 8 node indices of every cell, cells in cell-index order (x fastest), vertices in the
// local order above, as an array (the reference GridCells is checked against).
std::vector<std::array<std::int32_t, 8>> build_elements(const GridShape& shape);

// The same cells computed from the grid when asked for, instead of stored: 8 indices per cell
// would take 32 bytes per node. A random-access range of std::array<std::int32_t, 8>
// (by value): cells[c], cells.size(), and range-for; cell_at(n0) is the cell whose lower
// corner is node n0.
class GridCells {
 public:
  using Cell = std::array<std::int32_t, 8>;

  GridCells() = default;
  explicit GridCells(const GridShape& shape);

  std::size_t size() const { return static_cast<std::size_t>(count_); }
  bool empty() const { return count_ == 0; }
  // The lower corner node (local vertex 0) of cell c.
  std::int64_t corner(std::int64_t c) const;
  Cell operator[](std::size_t c) const { return cell_at(corner(static_cast<std::int64_t>(c))); }
  // The cell whose lower corner is node n0.
  Cell cell_at(std::int64_t n0) const {
    Cell e{};
    for (std::size_t v = 0; v < 8; ++v) e[v] = static_cast<std::int32_t>(n0 + step_[v]);
    return e;
  }

  class Iterator {
   public:
    using value_type = Cell;
    using difference_type = std::ptrdiff_t;
    Iterator(const GridCells* cells, std::size_t c) : cells_(cells), c_(c) {}
    Cell operator*() const { return (*cells_)[c_]; }
    Iterator& operator++() {
      ++c_;
      return *this;
    }
    bool operator==(const Iterator& other) const { return c_ == other.c_; }
    bool operator!=(const Iterator& other) const { return c_ != other.c_; }

   private:
    const GridCells* cells_;
    std::size_t c_;
  };
  Iterator begin() const { return {this, 0}; }
  Iterator end() const { return {this, size()}; }

 private:
  GridShape shape_;
  std::int64_t count_ = 0;
  std::array<std::int64_t, 8> step_{};  // node index step from vertex 0 to vertex v
};

using CellVertices = std::array<Eigen::Vector3d, 8>;

// The averaged edge vectors a, b, c of a cell.
struct EdgeVectors {
  Eigen::Vector3d a;
  Eigen::Vector3d b;
  Eigen::Vector3d c;
};
EdgeVectors averaged_edge_vectors(const CellVertices& x);

// V = a . (b x c).
double cell_volume(const CellVertices& x);

// V and its exact gradient with respect to the 8 vertex positions:
// dV/dx_v = (s_a (b x c) + s_b (c x a) + s_c (a x b)) / 4, with s_a = +1 if v is on the cell's
// +x face (bit 1 set) and -1 otherwise, s_b likewise for +y (bit 2), s_c for +z (bit 0).
// (The original's forces omit the 1/4: they are 4x this gradient,
// docs/original-code.md#volume-elements.)
double cell_volume_and_gradient(const CellVertices& x, CellVertices& gradient);

}  // namespace mresim::lattice
