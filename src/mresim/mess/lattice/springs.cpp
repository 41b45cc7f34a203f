#include "mresim/mess/lattice/springs.hpp"

#include <cmath>
#include <stdexcept>

namespace mresim::lattice {

double rest_length_factor(SpringKind kind) {
  switch (kind) {
    case SpringKind::edge:
      return 1.0;
    case SpringKind::face:
      return std::sqrt(2.0);
    case SpringKind::body:
      return std::sqrt(3.0);
  }
  return 0.0;
}

double constant_of(const SpringConstants& k, SpringKind kind) {
  switch (kind) {
    case SpringKind::edge:
      return k.edge;
    case SpringKind::face:
      return k.face;
    case SpringKind::body:
      return k.body;
  }
  return 0.0;
}

SpringKind kind_of_offset(const std::array<int, 3>& offset) {
  const int nonzero = (offset[0] != 0) + (offset[1] != 0) + (offset[2] != 0);
  if (nonzero == 1) return SpringKind::edge;
  if (nonzero == 2) return SpringKind::face;
  if (nonzero == 3) return SpringKind::body;
  throw std::invalid_argument("kind_of_offset: the zero offset is not a spring");
}

int cells_containing(const GridShape& shape, int ix, int iy, int iz,
                     const std::array<int, 3>& offset) {
  const std::array<int, 3> p{ix, iy, iz};
  int cells = 1;
  for (int a = 0; a < 3; ++a) {
    // Along an axis the spring spans, exactly one layer of cells holds it; along an axis it
    // does not span, the layers below and above node p hold it if they exist.
    if (offset[a] == 0) cells *= (p[a] > 0 ? 1 : 0) + (p[a] < shape.nodes[a] - 1 ? 1 : 0);
  }
  return cells;
}

int bulk_cells_containing(SpringKind kind) {
  switch (kind) {
    case SpringKind::edge:
      return 4;
    case SpringKind::face:
      return 2;
    case SpringKind::body:
      return 1;
  }
  return 1;
}

void SpringProperties::push_back(const Entry& entry) {
  std::size_t v = 0;
  while (v < table_.size() && !(table_[v] == entry)) ++v;
  if (v == table_.size()) {
    if (table_.size() == 256) {
      throw std::length_error("SpringProperties: more than 256 distinct spring properties");
    }
    table_.push_back(entry);
  }
  index_.push_back(static_cast<std::uint8_t>(v));
}

SpringSet build_springs(const GridShape& shape, double element_length,
                        const SpringConstants& polymer, const SpringConstants& particle,
                        const std::vector<std::int32_t>& particle_of_node,
                        ParticleSpringRule rule) {
  validate_grid_shape(shape);
  const bool has_particles = !particle_of_node.empty();
  if (has_particles && static_cast<std::int64_t>(particle_of_node.size()) != shape.node_count()) {
    throw std::invalid_argument("build_springs: particle_of_node must have one entry per node");
  }
  SpringSet set;
  set.element_length = element_length;
  const auto expected = static_cast<std::size_t>(closed_form_spring_counts(shape).total());
  set.first.reserve(expected);
  set.properties.reserve(expected);

  // Bulk constants of the three kinds, and the same divided by the bulk cell counts.
  const std::array<double, 3> polymer_per_cell{polymer.edge / 4.0, polymer.face / 2.0,
                                               polymer.body};
  const std::array<double, 3> particle_k{particle.edge, particle.face, particle.body};
  std::array<SpringKind, 13> kinds{};
  for (std::size_t n = 0; n < kForwardNeighbours.size(); ++n) {
    kinds[n] = kind_of_offset(kForwardNeighbours[n]);
  }

  for (int iy = 0; iy < shape.ny(); ++iy) {
    for (int ix = 0; ix < shape.nx(); ++ix) {
      for (int iz = 0; iz < shape.nz(); ++iz) {
        const int i = shape.node_index(ix, iy, iz);
        const std::int32_t pi = has_particles ? particle_of_node[i] : -1;
        for (std::size_t n = 0; n < kForwardNeighbours.size(); ++n) {
          const auto& d = kForwardNeighbours[n];
          const int jx = ix + d[0];
          const int jy = iy + d[1];
          const int jz = iz + d[2];
          if (jx < 0 || jx >= shape.nx() || jy < 0 || jy >= shape.ny() || jz < 0 ||
              jz >= shape.nz()) {
            continue;
          }
          const int j = shape.node_index(jx, jy, jz);
          const auto k = static_cast<std::size_t>(kinds[n]);
          const std::int32_t pj = has_particles ? particle_of_node[j] : -1;
          const bool is_particle =
              pi >= 0 && pj >= 0 && (rule == ParticleSpringRule::any_particle || pi == pj);
          set.first.push_back(i);
          set.properties.push_back(
              {is_particle ? particle_k[k]
                           : polymer_per_cell[k] * cells_containing(shape, ix, iy, iz, d),
               j - i, kinds[n], is_particle});
        }
      }
    }
  }
  return set;
}

SpringCounts closed_form_spring_counts(const GridShape& shape) {
  const std::int64_t nx = shape.nx();
  const std::int64_t ny = shape.ny();
  const std::int64_t nz = shape.nz();
  SpringCounts c;
  // Edge springs along axis a: (N_a - 1) per line; a line lies on 0, 1 or 2 outer faces
  // according to how many of its two transverse coordinates are extreme (N_b >= 2 each, so
  // every axis has exactly two extreme layers and N_b - 2 inner ones).
  const auto edge_lines = [&](std::int64_t along, std::int64_t b, std::int64_t cc) {
    c.edge.quarter += (along - 1) * 4;
    c.edge.half += (along - 1) * (2 * (b - 2) + 2 * (cc - 2));
    c.edge.full += (along - 1) * (b - 2) * (cc - 2);
  };
  edge_lines(nx, ny, nz);
  edge_lines(ny, nx, nz);
  edge_lines(nz, nx, ny);
  // Face diagonals in planes normal to axis a: 2 per square, (b-1)(c-1) squares per plane;
  // the 2 extreme planes are outer faces.
  const auto face_planes = [&](std::int64_t normal, std::int64_t b, std::int64_t cc) {
    c.face.half += (b - 1) * (cc - 1) * 4;
    c.face.full += (normal - 2) * 2 * (b - 1) * (cc - 1);
  };
  face_planes(nx, ny, nz);
  face_planes(ny, nx, nz);
  face_planes(nz, nx, ny);
  c.body.full = 4 * (nx - 1) * (ny - 1) * (nz - 1);
  return c;
}

}  // namespace mresim::lattice
