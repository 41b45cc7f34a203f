#include "mresim/mess/lattice/spheres.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <stdexcept>

namespace mresim::lattice {

namespace {

void validate_order(int discretization_order) {
  if (discretization_order < 1) {
    throw std::invalid_argument(fmt::format(
        "discretization_order = {} is not allowed: it must be >= 1", discretization_order));
  }
}

std::string centre_in_metres(const std::array<int, 3>& cell, double element_length) {
  return fmt::format("({:.6g}, {:.6g}, {:.6g}) m", (cell[0] + 0.5) * element_length,
                     (cell[1] + 0.5) * element_length, (cell[2] + 0.5) * element_length);
}

}  // namespace

std::vector<std::array<int, 3>> sphere_voxel_offsets(int discretization_order) {
  validate_order(discretization_order);
  const int n = discretization_order;
  const int limit = n * n + n;  // floor((n + 1/2)^2)
  std::vector<std::array<int, 3>> out;
  for (int i = -n; i <= n; ++i) {
    for (int j = -n; j <= n; ++j) {
      for (int k = -n; k <= n; ++k) {
        if (i * i + j * j + k * k <= limit) out.push_back({i, j, k});
      }
    }
  }
  return out;
}

std::vector<std::array<int, 3>> sphere_node_offsets(int discretization_order) {
  std::set<std::array<int, 3>> corners;  // lexicographic by (x, y, z)
  for (const auto& v : sphere_voxel_offsets(discretization_order)) {
    for (int dx = 0; dx <= 1; ++dx) {
      for (int dy = 0; dy <= 1; ++dy) {
        for (int dz = 0; dz <= 1; ++dz) corners.insert({v[0] + dx, v[1] + dy, v[2] + dz});
      }
    }
  }
  std::vector<std::array<int, 3>> out;
  out.reserve(corners.size());
  for (int dx = 0; dx <= 1; ++dx) {
    for (int dy = 0; dy <= 1; ++dy) {
      for (int dz = 0; dz <= 1; ++dz) out.push_back({dx, dy, dz});
    }
  }
  for (const auto& c : corners) {
    const bool centre_voxel_corner =
        c[0] >= 0 && c[0] <= 1 && c[1] >= 0 && c[1] <= 1 && c[2] >= 0 && c[2] <= 1;
    if (!centre_voxel_corner) out.push_back(c);
  }
  return out;
}

ParticleNodes voxelize_particles(const GridShape& shape,
                                 const std::vector<std::array<int, 3>>& centre_cells,
                                 int discretization_order, double element_length) {
  validate_grid_shape(shape);
  const auto offsets = sphere_node_offsets(discretization_order);
  const int n = discretization_order;
  ParticleNodes out;
  out.particle_of_node.assign(static_cast<std::size_t>(shape.node_count()), -1);
  out.nodes.reserve(centre_cells.size());
  for (std::size_t p = 0; p < centre_cells.size(); ++p) {
    const auto& c = centre_cells[p];
    for (int a = 0; a < 3; ++a) {
      // Nodes span c - n .. c + n + 1 along each axis; they must be interior: 1 .. N - 2.
      const int lo = c[a] - n;
      const int hi = c[a] + n + 1;
      if (lo < 1 || hi > shape.nodes[a] - 2) {
        const double lo_m = lo * element_length;
        const double hi_m = hi * element_length;
        const double box_m = (shape.nodes[a] - 1) * element_length;
        throw std::invalid_argument(fmt::format(
            "particle {} centred at {} is outside the box or touches its outer faces: along {} "
            "it spans [{:.6g}, {:.6g}] m, but particle nodes must lie strictly inside "
            "(0, {:.6g}) m",
            p, centre_in_metres(c, element_length), "xyz"[a], lo_m, hi_m, box_m));
      }
    }
    std::vector<std::int32_t> nodes;
    nodes.reserve(offsets.size());
    for (const auto& o : offsets) {
      const int node = shape.node_index(c[0] + o[0], c[1] + o[1], c[2] + o[2]);
      const std::int32_t other = out.particle_of_node[node];
      if (other >= 0) {
        throw std::invalid_argument(fmt::format(
            "particles {} and {} overlap: centred at {} and {} ({:.6g} m apart), their voxelized "
            "spheres share nodes; centres must be far enough apart that at least one layer of "
            "polymer nodes separates them",
            other, p, centre_in_metres(centre_cells[other], element_length),
            centre_in_metres(c, element_length),
            element_length *
                std::sqrt(static_cast<double>(
                    (c[0] - centre_cells[other][0]) * (c[0] - centre_cells[other][0]) +
                    (c[1] - centre_cells[other][1]) * (c[1] - centre_cells[other][1]) +
                    (c[2] - centre_cells[other][2]) * (c[2] - centre_cells[other][2])))));
      }
      out.particle_of_node[node] = static_cast<std::int32_t>(p);
      nodes.push_back(node);
    }
    out.nodes.push_back(std::move(nodes));
  }
  return out;
}

Eigen::VectorXd nodal_masses(const GridShape& shape, double element_length,
                             const std::vector<std::vector<std::int32_t>>& particle_nodes,
                             double particle_radius, double polymer_density, double iron_density) {
  const double cell_mass = polymer_density * element_length * element_length * element_length;
  Eigen::VectorXd m(shape.node_count());
  for (int iy = 0; iy < shape.ny(); ++iy) {
    for (int ix = 0; ix < shape.nx(); ++ix) {
      for (int iz = 0; iz < shape.nz(); ++iz) {
        const std::array<int, 3> p{ix, iy, iz};
        int cells = 1;  // cells having this node as a vertex
        for (int a = 0; a < 3; ++a) {
          cells *= (p[a] > 0 ? 1 : 0) + (p[a] < shape.nodes[a] - 1 ? 1 : 0);
        }
        m[shape.node_index(ix, iy, iz)] = cell_mass * cells / 8.0;  // eq. 4.54
      }
    }
  }
  const double particle_mass = iron_density * sphere_volume(particle_radius);
  for (const auto& nodes : particle_nodes) {
    const double node_mass = particle_mass / static_cast<double>(nodes.size());  // eq. 4.53
    for (const std::int32_t node : nodes) m[node] = node_mass;
  }
  return m;
}

}  // namespace mresim::lattice
