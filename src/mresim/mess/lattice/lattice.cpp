#include "mresim/mess/lattice/lattice.hpp"

#include "mresim/mess/lattice/volume_elements.hpp"

namespace mresim::lattice {

Eigen::Vector3d Lattice::box_lengths() const {
  return {(shape.nx() - 1) * element_length, (shape.ny() - 1) * element_length,
          (shape.nz() - 1) * element_length};
}

double Lattice::volume_fraction() const {
  return static_cast<double>(particle_count()) * sphere_volume(particle_radius) /
         box_lengths().prod();
}

Lattice build_lattice(const LatticeSpec& spec) {
  Lattice lat;
  lat.particle_radius = spec.particle_radius;
  lat.discretization_order = spec.discretization_order;
  lat.element_length = element_length(spec.particle_radius, spec.discretization_order);
  const double l_e = lat.element_length;

  // Stiffness first: it validates E, nu and A.
  lat.polymer = polymer_stiffness(spec.shear_modulus_rule, spec.youngs_modulus, spec.poisson_ratio,
                                  l_e, spec.stiffness_ratio);
  lat.particle_springs = particle_spring_constants(spec.shear_modulus_rule, spec.youngs_modulus,
                                                   spec.poisson_ratio, l_e, spec.stiffness_ratio);

  PlacedParticles placed =
      place_particles(spec.placement, spec.particle_radius, spec.discretization_order);
  lat.shape = placed.shape;
  lat.particle_centre_cells = std::move(placed.centre_cells);
  lat.particle_nodes = std::move(placed.particles.nodes);
  lat.particle_of_node = std::move(placed.particles.particle_of_node);
  for (const auto& c : lat.particle_centre_cells) {
    lat.particle_centres.emplace_back((c[0] + 0.5) * l_e, (c[1] + 0.5) * l_e, (c[2] + 0.5) * l_e);
  }

  const GridShape& shape = lat.shape;
  lat.positions.resize(3, shape.node_count());
  for (int iy = 0; iy < shape.ny(); ++iy) {
    for (int ix = 0; ix < shape.nx(); ++ix) {
      for (int iz = 0; iz < shape.nz(); ++iz) {
        lat.positions.col(shape.node_index(ix, iy, iz)) =
            Eigen::Vector3d(ix * l_e, iy * l_e, iz * l_e);
      }
    }
  }
  lat.node_types = node_type_codes(shape);
  for (const auto& nodes : lat.particle_nodes) {
    for (const std::int32_t n : nodes) lat.node_types[n] = node_type::kParticle;
  }

  lat.springs = build_springs(shape, l_e, lat.polymer.springs, lat.particle_springs,
                              lat.particle_of_node, spec.particle_spring_rule);
  lat.elements = GridCells(shape);
  lat.masses = nodal_masses(shape, l_e, lat.particle_nodes, spec.particle_radius,
                            spec.polymer_density, spec.iron_density);
  return lat;
}

}  // namespace mresim::lattice
