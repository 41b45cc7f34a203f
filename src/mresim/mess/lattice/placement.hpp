#pragma once

// Where the particles go and how big the box is (Sections 4.2.2, 4.3; Appendix A;
// docs/original-code.md#placement-and-box-size). Every placement ends with particle centres on cell
// centres and is checked: a particle outside the box (or touching its outer faces), or two
// particles sharing nodes, throws std::invalid_argument naming the particle(s) and their centres in
// metres.

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <numbers>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "mresim/mess/lattice/grid.hpp"
#include "mresim/mess/lattice/spheres.hpp"

namespace mresim::lattice {

// 'regular', 'regular_noisy', 'regular_anisotropic', 'regular_anisotropic_noisy' (the original's
// names; Appendix A's 'anisotropic_regular' and 'anisotropic_regular_noisy' are accepted too),
// particle volume fraction and particles per axis (Appendix A, Listing A.1). The box follows
// box_from_volume_fraction (grid.hpp); centres step by S_a voxels from the first centre, in
// the order x outer, y, z inner. Noisy variants shift each centre by an integer number of
// voxels drawn uniformly from {-1, 0, +1} per axis (portable generator, seeded by noise_seed).
struct RegularPlacement {
  double volume_fraction = 0.0;
  std::array<int, 3> particles_along_axes{1, 1, 2};
  bool anisotropic = false;
  // Relative system size along x, y, z; only used when anisotropic (Appendix A uses
  // (1/sqrt(f), 1/sqrt(f), f)).
  std::array<double, 3> anisotropy_factor{1.0, 1.0, 1.0};
  bool noisy = false;
  std::uint64_t noise_seed = 0;
};

// How a box given in metres becomes node counts.
enum class BoxRounding {
  nearest,            // N_a = round(L_a/l_e + 1) (docs/original-code.md#grid-and-node-numbering)
  seed_floor_divide,  // N_a = (L_a // l_e) + 1 with Python's float floor division: the
                      // original's 'by_hand' rule, one element short when L_a is an exact
                      // multiple of l_e (12 um -> 44 nodes, 18 um -> 66; Sections 4.3.1-4.3.3)
};
struct BoxSpec {
  Eigen::Vector3d lengths = Eigen::Vector3d::Zero();  // m
  BoxRounding rounding = BoxRounding::nearest;
};

// Particle centres given in metres ('by_hand'); each is moved to the centre of the cell that
// contains it, floor(x/l_e) + 1/2 in units of l_e (the original's rule).
struct ByHandPlacement {
  BoxSpec box;
  std::vector<Eigen::Vector3d> positions;  // m
};

// A straight chain of `count` particles along `axis` (0 = x, 1 = y, 2 = z), `separation` apart
// (centre to centre, m), centred on `centre` (default: the middle of box.lengths), then snapped
// as by hand. Fig. 4.20: 4 particles, 6 um, box 12 x 12 x 40 um with seed_floor_divide; the
// two-particle systems of Figs. 4.10-4.13 are chains of 2 at 6.5454 and 5.4545 um in that box.
struct ChainPlacement {
  BoxSpec box;
  int count = 2;
  double separation = 0.0;  // m
  int axis = 2;
  std::optional<Eigen::Vector3d> centre;  // m
};

// A helix about the z axis (Section 4.3.3, Fig. 4.24, Appendix A Listing A.2): particle i sits
// at centre + (r cos(i dphi), r sin(i dphi), (i - (count-1)/2) S_z), then snapped as by hand.
// Appendix A: 8 particles, dphi = 2 pi/8, S_z = 5 um, r = 0.5 .. 3.5 um, box 18 x 18 x 62 um
// (seed_floor_divide: 66 x 66 x 228 nodes), axis through (9, 9) um, first particle at z = 13.5 um.
struct HelixPlacement {
  BoxSpec box;
  int count = 8;
  double radius = 0.0;                         // R_helix, m
  double axial_separation = 5.0e-6;            // S_z, m
  double angle_step = std::numbers::pi / 4.0;  // dphi, rad
  std::optional<Eigen::Vector3d> centre;       // m; default: middle of box.lengths
};

using Placement = std::variant<RegularPlacement, ByHandPlacement, ChainPlacement, HelixPlacement>;

enum class PlacementKind {
  regular,
  regular_noisy,
  regular_anisotropic,
  regular_anisotropic_noisy,
  by_hand,
  chain,
  helix,
  none  // no particles: the polymer block the MR effect is measured against (a ByHandPlacement
        // without positions)
};
// Names as above ("by_hand", "chain", "helix", "none"); "anisotropic_regular" and
// "anisotropic_regular_noisy" are accepted as aliases. Anything else throws
// std::invalid_argument listing the allowed names.
PlacementKind parse_placement_kind(std::string_view name);
std::string to_string(PlacementKind kind);
PlacementKind kind_of(const Placement& placement);

// Node counts of a box given in metres.
GridShape shape_of_box(const BoxSpec& box, double element_length);

// Snaps a position in metres to the cell containing it; throws std::invalid_argument if it is
// outside [0, L) of the lattice (L = (N - 1) l_e), naming `what`.
std::array<int, 3> cell_of_position(const GridShape& shape, double element_length,
                                    const Eigen::Vector3d& position, const std::string& what);

// Particle centres (metres, before snapping) of the chain and helix placements.
std::vector<Eigen::Vector3d> chain_positions(const ChainPlacement& chain);
std::vector<Eigen::Vector3d> helix_positions(const HelixPlacement& helix);

// The outcome of a placement: box, centre cells and the rasterized particles.
struct PlacedParticles {
  GridShape shape;
  std::vector<std::array<int, 3>> centre_cells;  // cell (voxel) holding each particle's centre
  ParticleNodes particles;
};

// Sizes the box, places and rasterizes the particles; throws std::invalid_argument for invalid
// parameters, particles outside the box and overlapping particles.
PlacedParticles place_particles(const Placement& placement, double particle_radius,
                                int discretization_order);

}  // namespace mresim::lattice
