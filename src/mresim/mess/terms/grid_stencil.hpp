#pragma once

// The lattice's springs and cells as stencils over the regular grid, for the per-node gathers
// of the elastic kernels (elastic_terms.cpp): every node adds up the contributions of its own
// springs or cells in a fixed order, so that no two threads write one node and the result does
// not depend on the number of threads. The order is increasing spring or cell index, the order
// of a gather over explicit node -> spring/cell lists, which the stencils replace: the results
// are bitwise those of such lists, without their memory (112 bytes per node for the springs'
// lists, 40 for the cells') and without reading them and the springs' node indices back in every
// gather. Neighbouring positions come from the three grid planes around a node, which stay in
// the cache.
//
// Springs (SpringStencil). build_springs (lattice/springs.hpp) numbers the springs in node
// order and, per node, in the order of the 13 forward neighbour offsets that stay inside the
// box. So the spring of node n along offset o is
//     s = first_spring[n] + (number of n's present offsets before o),
// and the springs incident to a node, in increasing spring index, are first its backward
// springs (from the lower-index nodes m = n - delta(o), in increasing m, i.e. by decreasing
// index step delta(o)) and then its own forward springs in offset order. The stencil keeps
// 10 bytes per node: first_spring and the 13-bit mask of present forward offsets.
//
// Cells (CellStencil). build_elements (lattice/volume_elements.hpp) numbers cell (cx, cy, cz)
// as cx + Cx (cy + Cy cz), so the up to eight cells of node (ix, iy, iz), cells (ix - dx,
// iy - dy, iz - dz) with dx, dy, dz in {0, 1}, come in increasing index for dz, dy, dx each
// running 1, 0; the node is the cell's vertex with vertex_offset (dx, dy, dz). No data.

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

#include "mresim/mess/lattice/lattice.hpp"
#include "mresim/mess/lattice/springs.hpp"
#include "mresim/mess/lattice/volume_elements.hpp"
#include "mresim/mess/system/fixed_order.hpp"

namespace mresim::mess {

// Node index change of each forward offset (lattice::kForwardNeighbours) on `shape`'s grid.
std::array<std::int64_t, 13> forward_offset_deltas(const lattice::GridShape& shape);
// The forward offsets by decreasing index change: the order in which a node's backward
// springs (from the lower-index nodes n - delta(o), in increasing index) come. Two offsets can
// share a delta on a thin grid (nz = 2), but then at most one of them stays in the box for any
// node, so their order does not matter.
std::array<int, 13> backward_offset_order(const std::array<std::int64_t, 13>& deltas);

// The up to eight cells of node (ix, iy, iz) are (ix - dx, iy - dy, iz - dz) for these
// offsets (dx, dy, dz), listed in increasing cell index (lattice::GridShape::cell_index); the
// node is the cell's local vertex 2 dx + 4 dy + dz (lattice::vertex_offset).
inline constexpr std::array<std::array<int, 3>, 8> kCellsOfNode = {
    {{1, 1, 1}, {0, 1, 1}, {1, 0, 1}, {0, 0, 1}, {1, 1, 0}, {0, 1, 0}, {1, 0, 0}, {0, 0, 0}}};

class SpringStencil {
 public:
  SpringStencil() = default;
  // Throws std::invalid_argument unless lattice.springs is exactly the forward-neighbour set of
  // its grid in build_springs' order (every lattice from build_lattice is).
  explicit SpringStencil(const lattice::Lattice& lattice);

  std::int64_t node_count() const { return static_cast<std::int64_t>(mask_.size()); }
  std::int64_t spring_count() const { return spring_count_; }
  // The springs of the nodes below `node` (node_count() gives spring_count()).
  std::int64_t first_spring(std::int64_t node) const {
    return node < node_count() ? first_spring_[static_cast<std::size_t>(node)] : spring_count_;
  }
  // The node index change of each forward offset, and the offsets by decreasing change (the
  // order of a node's backward springs).
  const std::array<std::int64_t, 13>& deltas() const { return delta_; }
  const std::array<int, 13>& backward_order() const { return backward_order_; }
  const lattice::GridShape& shape() const { return shape_; }

  // For every node n: g = out.col(n); then, for each spring s incident to n in increasing s,
  // g += contribution(s, first, second) if n is the spring's second end, g -= ... if it is the
  // first; out.col(n) = g. `contribution` returns an Eigen::Vector3d.
  template <class Contribution>
  void gather(Eigen::Matrix3Xd& out, Contribution&& contribution) const;

  // The first part of gather's sum for one node, at grid coordinates (ix, iy, iz): g plus the
  // contributions of its backward springs (those with `node` as second end), in increasing
  // spring index. Its forward springs come after them (for_each_forward_spring).
  template <class Contribution>
  Eigen::Vector3d gather_backward(std::int64_t node, int ix, int iy, int iz, Eigen::Vector3d g,
                                  Contribution&& contribution) const;

  // visit(s, offset, second) for the forward springs of `node` (those with `node` as first
  // end), in increasing s: the order in which build_springs numbers them.
  template <class Visit>
  void for_each_forward_spring(std::int64_t node, Visit&& visit) const {
    const unsigned mask = mask_[static_cast<std::size_t>(node)];
    std::int64_t s = first_spring_[static_cast<std::size_t>(node)];
    for (int o = 0; o < 13; ++o) {
      if (((mask >> static_cast<unsigned>(o)) & 1U) == 0) continue;
      visit(s++, o, node + delta_[static_cast<std::size_t>(o)]);
    }
  }

 private:
  // first_spring[node] + the number of the node's present offsets below `offset` (a table
  // lookup: the portable build has no popcount instruction).
  std::int64_t spring_of(std::int64_t node, int offset) const {
    const auto lower = static_cast<unsigned>(mask_[static_cast<std::size_t>(node)]) &
                       ((1U << static_cast<unsigned>(offset)) - 1U);
    return first_spring_[static_cast<std::size_t>(node)] + bits_set_[lower];
  }

  lattice::GridShape shape_;
  std::array<std::int64_t, 13> delta_{};    // node index change of each forward offset
  std::array<int, 13> backward_order_{};    // offsets by decreasing delta
  std::vector<std::int64_t> first_spring_;  // per node
  std::vector<std::uint16_t> mask_;         // per node: bit o = offset o stays in the box
  std::vector<std::uint8_t> bits_set_;      // number of bits set, for every 13-bit mask
  std::int64_t spring_count_ = 0;
};

template <class Contribution>
void SpringStencil::gather(Eigen::Matrix3Xd& out, Contribution&& contribution) const {
  const int nx = shape_.nx();
  const int ny = shape_.ny();
  const int nz = shape_.nz();
  const std::int64_t rows = std::int64_t{nx} * ny;  // node index = iz + nz (ix + nx iy)
#pragma omp parallel for schedule(static) if (node_count() >= detail::kParallelMinimum / 4)
  for (std::int64_t row = 0; row < rows; ++row) {
    const int ix = static_cast<int>(row % nx);
    const int iy = static_cast<int>(row / nx);
    for (int iz = 0; iz < nz; ++iz) {
      const std::int64_t n = iz + nz * row;
      Eigen::Vector3d g = gather_backward(n, ix, iy, iz, out.col(n), contribution);
      for_each_forward_spring(
          n, [&](std::int64_t s, int, std::int64_t second) { g -= contribution(s, n, second); });
      out.col(n) = g;
    }
  }
}

template <class Contribution>
Eigen::Vector3d SpringStencil::gather_backward(std::int64_t n, int ix, int iy, int iz,
                                               Eigen::Vector3d g,
                                               Contribution&& contribution) const {
  const int nx = shape_.nx();
  const int ny = shape_.ny();
  const int nz = shape_.nz();
  // Away from the box's faces every backward neighbour exists (the usual case).
  const bool inside = ix > 0 && ix < nx - 1 && iy > 0 && iy < ny - 1 && iz > 0 && iz < nz - 1;
  for (const int o : backward_order_) {
    if (!inside) {
      const auto& d = lattice::kForwardNeighbours[static_cast<std::size_t>(o)];
      const int mx = ix - d[0];
      const int my = iy - d[1];
      const int mz = iz - d[2];
      if (mx < 0 || mx >= nx || my < 0 || my >= ny || mz < 0 || mz >= nz) continue;
    }
    const std::int64_t m = n - delta_[static_cast<std::size_t>(o)];
    g += contribution(spring_of(m, o), m, n);
  }
  return g;
}

class CellStencil {
 public:
  CellStencil() = default;
  explicit CellStencil(const lattice::GridShape& shape) : shape_(shape) {}

  // For every node n: g = out.col(n); g += contribution(c, v) for each cell c holding n, in
  // increasing c, v = n's local vertex in c (lattice::vertex_offset); out.col(n) = g.
  // `contribution` returns an Eigen::Vector3d.
  template <class Contribution>
  void gather(Eigen::Matrix3Xd& out, Contribution&& contribution) const;

  // The same for the node at grid coordinates (ix, iy, iz): returns g plus its cells'
  // contributions, in increasing cell index.
  template <class Contribution>
  Eigen::Vector3d gather_node(int ix, int iy, int iz, Eigen::Vector3d g,
                              Contribution&& contribution) const;

 private:
  lattice::GridShape shape_;
};

template <class Contribution>
void CellStencil::gather(Eigen::Matrix3Xd& out, Contribution&& contribution) const {
  const int nx = shape_.nx();
  const int ny = shape_.ny();
  const int nz = shape_.nz();
  const std::int64_t rows = std::int64_t{nx} * ny;  // node index = iz + nz (ix + nx iy)
#pragma omp parallel for schedule(static) if (rows * nz >= detail::kParallelMinimum / 4)
  for (std::int64_t row = 0; row < rows; ++row) {
    const int ix = static_cast<int>(row % nx);
    const int iy = static_cast<int>(row / nx);
    for (int iz = 0; iz < nz; ++iz) {
      const std::int64_t n = iz + nz * row;
      out.col(n) = gather_node(ix, iy, iz, out.col(n), contribution);
    }
  }
}

template <class Contribution>
Eigen::Vector3d CellStencil::gather_node(int ix, int iy, int iz, Eigen::Vector3d g,
                                         Contribution&& contribution) const {
  const int nx = shape_.nx();
  const int ny = shape_.ny();
  const int nz = shape_.nz();
  const std::int64_t cx = nx - 1;
  const std::int64_t cy = ny - 1;
  // Away from the box's faces all eight cells exist (the usual case).
  const bool inside = ix > 0 && ix < nx - 1 && iy > 0 && iy < ny - 1 && iz > 0 && iz < nz - 1;
  const std::int64_t corner_cell = ix + cx * (iy + cy * iz);  // the cell at offset (0, 0, 0)
#pragma GCC unroll 8
  for (const auto& [dx, dy, dz] : kCellsOfNode) {
    if (!inside && (ix - dx < 0 || ix - dx >= nx - 1 || iy - dy < 0 || iy - dy >= ny - 1 ||
                    iz - dz < 0 || iz - dz >= nz - 1)) {
      continue;
    }
    const std::int64_t cell = corner_cell - (dx + cx * (dy + cy * dz));
    g += contribution(cell, 2 * dx + 4 * dy + dz);
  }
  return g;
}

}  // namespace mresim::mess
