#pragma once

// The assembled lattice of the 3D model (Chapter 4, MESS): nodes, springs, volume elements,
// particles and masses, built from a plain LatticeSpec (no file formats here). Geometry and
// stiffness only; the energy terms live elsewhere.

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

#include "mresim/mess/lattice/grid.hpp"
#include "mresim/mess/lattice/placement.hpp"
#include "mresim/mess/lattice/spheres.hpp"
#include "mresim/mess/lattice/springs.hpp"
#include "mresim/mess/lattice/stiffness.hpp"
#include "mresim/mess/lattice/volume_elements.hpp"

namespace mresim::lattice {

struct LatticeSpec {
  // The model profile's lattice rules (mess/profile/model_profile.hpp writes them).
  ShearModulusRule shear_modulus_rule = ShearModulusRule::from_youngs_and_poisson;
  ParticleSpringRule particle_spring_rule = ParticleSpringRule::same_particle;
  double youngs_modulus = 9.0e3;    // Pa, polymer
  double poisson_ratio = 0.47;      // polymer, in (-1, 0.5)
  double stiffness_ratio = 1.0;     // A = k_f/k_c (Section 4.2.1)
  double particle_radius = 1.5e-6;  // m
  int discretization_order = 5;     // n_d: particles are 2 n_d + 1 voxels across
  Placement placement = RegularPlacement{};
  double polymer_density = kPolymerDensity;  // kg/m^3
  double iron_density = kIronDensity;        // kg/m^3
};

struct Lattice {
  double element_length = 0.0;  // l_e, m
  GridShape shape;

  Eigen::Matrix3Xd positions;           // initial node positions (column = node index), m
  std::vector<std::int8_t> node_types;  // codes of grid.hpp; particle nodes are -1
  Eigen::VectorXd masses;               // kg per node

  SpringSet springs;
  GridCells elements;  // the cells' nodes, local vertex order of volume_elements.hpp

  LatticeStiffness polymer;          // polymer spring constants and kappa (used in every cell)
  SpringConstants particle_springs;  // constants of particle springs

  double particle_radius = 0.0;  // m
  int discretization_order = 0;
  std::vector<std::vector<std::int32_t>> particle_nodes;  // first 8: centre voxel's corners
  std::vector<std::int32_t> particle_of_node;             // -1 for polymer nodes
  std::vector<std::array<int, 3>> particle_centre_cells;
  std::vector<Eigen::Vector3d> particle_centres;  // m (centres of those cells)

  std::int64_t node_count() const { return shape.node_count(); }
  std::int64_t cell_count() const { return shape.cell_count(); }
  std::size_t particle_count() const { return particle_nodes.size(); }
  // (N_a - 1) l_e.
  Eigen::Vector3d box_lengths() const;
  // N_p (4/3 pi R^3) / (L_x L_y L_z), eq. 4.50 (the original's reported volume fraction).
  double volume_fraction() const;
};

// Builds everything; throws std::invalid_argument for invalid material parameters, placements,
// particles outside the box or overlapping.
Lattice build_lattice(const LatticeSpec& spec);

}  // namespace mresim::lattice
