#include "mresim/mess/lattice/volume_elements.hpp"

#include <Eigen/Geometry>

namespace mresim::lattice {

std::vector<std::array<std::int32_t, 8>> build_elements(const GridShape& shape) {
  validate_grid_shape(shape);
  const auto cells = shape.cells();
  std::vector<std::array<std::int32_t, 8>> elements;
  elements.reserve(static_cast<std::size_t>(shape.cell_count()));
  for (int iz = 0; iz < cells[2]; ++iz) {
    for (int iy = 0; iy < cells[1]; ++iy) {
      for (int ix = 0; ix < cells[0]; ++ix) {
        std::array<std::int32_t, 8> e{};
        for (int v = 0; v < 8; ++v) {
          const auto o = vertex_offset(v);
          e[v] = shape.node_index(ix + o[0], iy + o[1], iz + o[2]);
        }
        elements.push_back(e);
      }
    }
  }
  return elements;
}

GridCells::GridCells(const GridShape& shape) : shape_(shape), count_(shape.cell_count()) {
  validate_grid_shape(shape);
  for (int v = 0; v < 8; ++v) {
    const auto o = vertex_offset(v);
    step_[static_cast<std::size_t>(v)] = shape.node_index(o[0], o[1], o[2]);
  }
}

std::int64_t GridCells::corner(std::int64_t c) const {
  const auto cells = shape_.cells();
  const std::int64_t cx = c % cells[0];
  const std::int64_t rest = c / cells[0];
  const std::int64_t cy = rest % cells[1];
  const std::int64_t cz = rest / cells[1];
  return cz + std::int64_t{shape_.nz()} * (cx + std::int64_t{shape_.nx()} * cy);
}

EdgeVectors averaged_edge_vectors(const CellVertices& x) {
  EdgeVectors e;
  e.a = 0.25 * (x[2] - x[0] + x[3] - x[1] + x[6] - x[4] + x[7] - x[5]);  // eq. 4.45
  e.b = 0.25 * (x[4] - x[0] + x[6] - x[2] + x[5] - x[1] + x[7] - x[3]);  // eq. 4.46
  e.c = 0.25 * (x[1] - x[0] + x[3] - x[2] + x[5] - x[4] + x[7] - x[6]);  // eq. 4.47
  return e;
}

double cell_volume(const CellVertices& x) {
  const EdgeVectors e = averaged_edge_vectors(x);
  return e.a.dot(e.b.cross(e.c));  // eq. 4.48
}

double cell_volume_and_gradient(const CellVertices& x, CellVertices& gradient) {
  const EdgeVectors e = averaged_edge_vectors(x);
  const Eigen::Vector3d bxc = e.b.cross(e.c);  // dV/da
  const Eigen::Vector3d cxa = e.c.cross(e.a);  // dV/db
  const Eigen::Vector3d axb = e.a.cross(e.b);  // dV/dc
  for (int v = 0; v < 8; ++v) {
    // da/dx_v = s_a/4 (identity) etc.
    const double sa = (v & 2) ? 0.25 : -0.25;
    const double sb = (v & 4) ? 0.25 : -0.25;
    const double sc = (v & 1) ? 0.25 : -0.25;
    gradient[v] = sa * bxc + sb * cxa + sc * axb;
  }
  return e.a.dot(bxc);
}

}  // namespace mresim::lattice
