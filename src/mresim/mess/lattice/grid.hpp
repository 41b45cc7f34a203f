#pragma once

// The regular grid of nodes and cubic cells (Section 4.2.2) and its numbering, as in the
// original code (docs/original-code.md#grid-and-node-numbering, #volume-elements):
//  - node (ix, iy, iz) has index iz + Nz*ix + Nz*Nx*iy (z fastest, then x, then y) and initial
//    position (ix, iy, iz) * l_e;
//  - cell (ix, iy, iz), the cube with lower corner at node (ix, iy, iz), has index
//    ix + Cx*iy + Cx*Cy*iz (x fastest), C_a = N_a - 1;
//  - node type codes: 0 interior, 1-6 faces, 7-18 edges, 19-26 corners, -1 particle.

#include <array>
#include <cstdint>
#include <vector>

namespace mresim::lattice {

// eq. 4.49: l_e = 2R/(2 n_d + 1) (computed as R/(n_d + 1/2), bit-identical to the original).
// Throws std::invalid_argument unless R > 0 and n_d >= 1 (n_d = 0 would be a one-voxel sphere,
// which the original rejects as well).
double element_length(double particle_radius, int discretization_order);

// Nodes along one axis for a box of length L: round(L/l_e + 1), ties to even as Python's round
// (docs/original-code.md#grid-and-node-numbering). The box is then exactly (N - 1) l_e long.
int nodes_along_axis(double length, double element_length);

// Python's float floor division a // b (CPython float_floor_div: via fmod, so 12e-6 // l_e is
// 43, not 44, for l_e = 3e-6/11). The original's 'by_hand' runs take their element counts
// this way, which is how the dissertation's 44x44x147 and 66x66x228 node counts arise
// (docs/original-code.md#placement-and-box-size).
double python_floor_divide(double a, double b);

// Python's round(x, 1) followed by int(): the original's particle spacing in voxels
// (docs/original-code.md#placement-and-box-size). Equals floor(x) unless x's first decimal rounds
// up to the next integer (x >= k + 0.95). Only x >= 0 is meaningful.
int seed_spacing_voxels(double x);

// Node counts per axis (x, y, z), each >= 2.
struct GridShape {
  std::array<int, 3> nodes{2, 2, 2};

  int nx() const { return nodes[0]; }
  int ny() const { return nodes[1]; }
  int nz() const { return nodes[2]; }
  std::array<int, 3> cells() const { return {nodes[0] - 1, nodes[1] - 1, nodes[2] - 1}; }
  std::int64_t node_count() const;
  std::int64_t cell_count() const;

  // iz + Nz*ix + Nz*Nx*iy.
  int node_index(int ix, int iy, int iz) const { return iz + nodes[2] * (ix + nodes[0] * iy); }
  // Inverse of node_index: {ix, iy, iz}.
  std::array<int, 3> node_coordinates(int node) const;
  // ix + Cx*iy + Cx*Cy*iz with C = nodes - 1.
  int cell_index(int ix, int iy, int iz) const {
    return ix + (nodes[0] - 1) * (iy + (nodes[1] - 1) * iz);
  }
  std::array<int, 3> cell_coordinates(int cell) const;
};

// Throws std::invalid_argument unless every axis has at least 2 nodes and the node count fits
// the 32-bit node indices used throughout.
void validate_grid_shape(const GridShape& shape);

// Node type codes (docs/original-code.md#grid-and-node-numbering).
namespace node_type {
inline constexpr std::int8_t kParticle = -1;
inline constexpr std::int8_t kInterior = 0;
// faces
inline constexpr std::int8_t kLeft = 1, kRight = 2, kTop = 3, kBottom = 4, kFront = 5, kBack = 6;
// edges
inline constexpr std::int8_t kLeftTop = 7, kLeftBottom = 8, kLeftFront = 9, kLeftBack = 10;
inline constexpr std::int8_t kRightTop = 11, kRightBottom = 12, kRightFront = 13, kRightBack = 14;
inline constexpr std::int8_t kTopFront = 15, kTopBack = 16, kBottomFront = 17, kBottomBack = 18;
// corners, named by their (x, y, z) extremes
inline constexpr std::int8_t kCorner000 = 19, kCornerX00 = 20, kCorner0Y0 = 21, kCorner00Z = 22,
                             kCornerXY0 = 23, kCornerX0Z = 24, kCorner0YZ = 25, kCornerXYZ = 26;
}  // namespace node_type

// Geometric class of a node on the outer box.
enum class NodeClass { interior, face, edge, corner, particle };
NodeClass node_class(std::int8_t type_code);

// Type code of a node from its position in the box (never kParticle).
std::int8_t node_type_code(const GridShape& shape, int ix, int iy, int iz);
// Codes of all nodes, indexed by node index (no particle marking).
std::vector<std::int8_t> node_type_codes(const GridShape& shape);

// The six outer faces, by the original's names: left/right x = 0/max, front/back y = 0/max,
// bottom/top z = 0/max.
enum class Face { left, right, front, back, bottom, top };
// Indices of the nodes on one face (edges and corners included), in increasing index order.
std::vector<int> face_nodes(const GridShape& shape, Face face);

// System size from a volume fraction (eqs. 4.50-4.52 and the original's rule,
// docs/original-code.md#placement-and-box-size): s = (V_p/Phi)^(1/3) is the side of the cube
// holding one particle, L_a = n_a s f_a (f = anisotropy factor, 1 for isotropic), N_a =
// round(L_a/l_e + 1). Spacing in voxels S = int(round(s/l_e, 1)), S_a = int(S f_a); the first
// centre per axis is E_a/2 (+1/2 if E_a is even), E_a = C_a - S_a (n_a - 1), so centres sit on cell
// centres.
struct VolumeFractionBox {
  GridShape shape;
  double cube_side = 0.0;                // s, m
  std::array<double, 3> lengths{};       // L_a before rounding, m
  std::array<int, 3> spacing_voxels{};   // S_a
  std::array<double, 3> first_centre{};  // in units of l_e (half-integers)
};
// Throws std::invalid_argument for Phi outside (0, 1), n_a < 1, f_a <= 0, or spacings below 1.
VolumeFractionBox box_from_volume_fraction(double particle_radius, double element_length,
                                           double volume_fraction,
                                           const std::array<int, 3>& particles_along_axes,
                                           const std::array<double, 3>& anisotropy_factor = {
                                               1.0, 1.0, 1.0});

// V_p = 4/3 pi R^3.
double sphere_volume(double radius);

}  // namespace mresim::lattice
