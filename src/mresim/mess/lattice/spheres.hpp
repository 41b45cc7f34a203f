#pragma once

// Voxelized spherical particles and nodal masses (Section 4.2.2, Fig. 4.2, eqs. 4.53-4.54;
// docs/original-code.md#particles and #nodal-masses).
//
// A particle of discretization order n_d is centred on a cell (voxel) centre; the voxel at
// integer offset (i, j, k) from the centre voxel belongs to it iff its centre lies within
// R = (n_d + 1/2) l_e of the particle centre: i^2 + j^2 + k^2 <= (n_d + 1/2)^2, i.e.
// <= n_d^2 + n_d for integers (the original's floor(r_v^2) test). The particle is therefore
// 2 n_d + 1 voxels across. Its nodes are all corners of its voxels.

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

#include "mresim/mess/lattice/grid.hpp"

namespace mresim::lattice {

inline constexpr double kPolymerDensity = 965.0;  // kg/m^3 (PDMS, eq. 4.54)
inline constexpr double kIronDensity = 7860.0;    // kg/m^3 (eq. 4.53)

// Offsets (i, j, k) of the voxels of one particle from its centre voxel, lexicographic.
// Throws std::invalid_argument for n_d < 1.
std::vector<std::array<int, 3>> sphere_voxel_offsets(int discretization_order);

// Offsets of the particle's nodes from the lower corner of its centre voxel. As in the original,
// the first 8 are the corners of the centre voxel (so their mean is the particle centre), the
// rest follow sorted lexicographically by (x, y, z); the first 8 are lexicographic too.
std::vector<std::array<int, 3>> sphere_node_offsets(int discretization_order);

// Particles rasterized on a grid.
struct ParticleNodes {
  // Node indices of each particle, in the order of sphere_node_offsets.
  std::vector<std::vector<std::int32_t>> nodes;
  // Per node: the particle holding it, or -1 for polymer nodes.
  std::vector<std::int32_t> particle_of_node;
};

// Rasterizes particles centred on the given cells (cell coordinates of each centre voxel).
// Throws std::invalid_argument, naming the particle(s) and centre(s) in metres (l_e is only
// used for messages), if a particle's nodes leave the box or touch its outer faces (particle
// nodes must be interior nodes), or if two particles share a node (overlap or touch).
ParticleNodes voxelize_particles(const GridShape& shape,
                                 const std::vector<std::array<int, 3>>& centre_cells,
                                 int discretization_order, double element_length);

// Nodal masses (eqs. 4.53, 4.54): a polymer node gets rho_polymer l_e^3 times (cells that have
// it as a vertex)/8, i.e. 1, 1/2, 1/4, 1/8 for interior, face, edge and corner nodes; a particle
// node gets rho_iron (4/3 pi R^3) / (nodes per particle), the exact sphere's mass shared out.
// Polymer nodes next to particles keep the full polymer mass, as in the original.
Eigen::VectorXd nodal_masses(const GridShape& shape, double element_length,
                             const std::vector<std::vector<std::int32_t>>& particle_nodes,
                             double particle_radius, double polymer_density = kPolymerDensity,
                             double iron_density = kIronDensity);

}  // namespace mresim::lattice
