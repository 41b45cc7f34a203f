// The geometry a 3D run file implies, without building the lattice: the box, the placed and
// voxelized particles (the lattice's own placement code, which is also what validates them) and
// the spring counts (closed forms for the box, a walk over particle nodes for the stiff ones).

#include <fmt/format.h>

#include <stdexcept>

#include "mresim/mess/lattice/springs.hpp"
#include "mresim/mess/run_file/mess_spec.hpp"

namespace mresim::mess_config {

namespace {

lattice::GridShape box_shape(const lattice::LatticeSpec& spec, double l_e) {
  if (const auto* r = std::get_if<lattice::RegularPlacement>(&spec.placement)) {
    const std::array<double, 3> unit{1.0, 1.0, 1.0};
    return lattice::box_from_volume_fraction(spec.particle_radius, l_e, r->volume_fraction,
                                             r->particles_along_axes,
                                             r->anisotropic ? r->anisotropy_factor : unit)
        .shape;
  }
  if (const auto* h = std::get_if<lattice::ByHandPlacement>(&spec.placement)) {
    return lattice::shape_of_box(h->box, l_e);
  }
  if (const auto* c = std::get_if<lattice::ChainPlacement>(&spec.placement)) {
    return lattice::shape_of_box(c->box, l_e);
  }
  return lattice::shape_of_box(std::get<lattice::HelixPlacement>(spec.placement).box, l_e);
}

// Springs from a particle node to its forward neighbours that get the particle constants.
ParticleSpringCounts count_particle_springs(const lattice::GridShape& shape,
                                            const lattice::ParticleNodes& particles,
                                            lattice::ParticleSpringRule rule) {
  ParticleSpringCounts counts;
  for (std::size_t p = 0; p < particles.nodes.size(); ++p) {
    for (const std::int32_t node : particles.nodes[p]) {
      const auto c = shape.node_coordinates(node);
      for (const auto& offset : lattice::kForwardNeighbours) {
        const std::array<int, 3> n{c[0] + offset[0], c[1] + offset[1], c[2] + offset[2]};
        bool inside = true;
        for (int a = 0; a < 3; ++a) inside = inside && n[a] >= 0 && n[a] < shape.nodes[a];
        if (!inside) continue;
        const std::int32_t other =
            particles
                .particle_of_node[static_cast<std::size_t>(shape.node_index(n[0], n[1], n[2]))];
        const bool stiff = rule == lattice::ParticleSpringRule::any_particle
                               ? other >= 0
                               : other == static_cast<std::int32_t>(p);
        if (!stiff) continue;
        switch (lattice::kind_of_offset(offset)) {
          case lattice::SpringKind::edge:
            ++counts.edge;
            break;
          case lattice::SpringKind::face:
            ++counts.face;
            break;
          case lattice::SpringKind::body:
            ++counts.body;
            break;
        }
      }
    }
  }
  return counts;
}

}  // namespace

MessGeometry derive_geometry(const lattice::LatticeSpec& spec) {
  MessGeometry g;
  g.element_length = lattice::element_length(spec.particle_radius, spec.discretization_order);
  const lattice::GridShape shape = box_shape(spec, g.element_length);
  if (shape.node_count() > kMaxNodes) {
    throw std::invalid_argument(
        fmt::format("the lattice would have {} nodes ({} x {} x {}); at most {} are supported",
                    shape.node_count(), shape.nx(), shape.ny(), shape.nz(), kMaxNodes));
  }
  const lattice::PlacedParticles placed =
      lattice::place_particles(spec.placement, spec.particle_radius, spec.discretization_order);
  g.shape = placed.shape;
  g.box_lengths =
      Eigen::Vector3d((g.shape.nx() - 1) * g.element_length, (g.shape.ny() - 1) * g.element_length,
                      (g.shape.nz() - 1) * g.element_length);
  g.centre_cells = placed.centre_cells;
  for (const auto& c : g.centre_cells) {
    g.particle_centres.emplace_back((c[0] + 0.5) * g.element_length,
                                    (c[1] + 0.5) * g.element_length,
                                    (c[2] + 0.5) * g.element_length);
  }
  g.nodes_per_particle =
      static_cast<std::int64_t>(lattice::sphere_node_offsets(spec.discretization_order).size());
  g.springs = lattice::closed_form_spring_counts(g.shape);
  g.particle_springs = count_particle_springs(g.shape, placed.particles, spec.particle_spring_rule);
  g.volume_fraction = static_cast<double>(g.particle_count()) *
                      lattice::sphere_volume(spec.particle_radius) / g.box_lengths.prod();
  return g;
}

}  // namespace mresim::mess_config
