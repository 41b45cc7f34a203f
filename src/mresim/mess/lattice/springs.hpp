#pragma once

// The springs of the lattice (Sections 4.2.1-4.2.2; docs/original-code.md#springs): every node is
// joined to its 26 neighbours by edge, face-diagonal and body-diagonal springs. Each spring is
// generated once, from its lower-index node, through the 13 "forward" neighbour offsets.
//
// Stiffness: a cell holds 1/4 of each of its 12 edge springs, 1/2 of each of its 12 face
// diagonals and all of its 4 body diagonals (eqs. 4.23-4.27), so a spring's stiffness is the
// bulk constant times (cells containing it)/(4, 2 or 1): springs in an outer face get 1/2,
// edge springs along an outer edge line 1/4. This equals the original's node-type rules for
// every box with at least 3 nodes per axis (see docs/lattice.md). Springs joining two particle
// nodes get the particle constants instead, unweighted.

#include <array>
#include <cstdint>
#include <vector>

#include "mresim/mess/lattice/grid.hpp"
#include "mresim/mess/lattice/stiffness.hpp"

namespace mresim::lattice {

enum class SpringKind : std::uint8_t { edge = 0, face = 1, body = 2 };

// Rest length / l_e: 1, sqrt(2), sqrt(3).
double rest_length_factor(SpringKind kind);
// The bulk constant of that kind.
double constant_of(const SpringConstants& k, SpringKind kind);

// The 13 forward neighbour offsets (dx, dy, dz), in the original's order: +z, +x, +y (edges);
// (+y,-z), (+y,+z), (-x,+y), (+x,-z), (+x,+z), (+x,+y) (face diagonals); (-x,+y,-z),
// (-x,+y,+z), (+x,+y,-z), (+x,+y,+z) (body diagonals). Each raises the node index.
inline constexpr std::array<std::array<int, 3>, 13> kForwardNeighbours = {{{0, 0, 1},
                                                                           {1, 0, 0},
                                                                           {0, 1, 0},
                                                                           {0, 1, -1},
                                                                           {0, 1, 1},
                                                                           {-1, 1, 0},
                                                                           {1, 0, -1},
                                                                           {1, 0, 1},
                                                                           {1, 1, 0},
                                                                           {-1, 1, -1},
                                                                           {-1, 1, 1},
                                                                           {1, 1, -1},
                                                                           {1, 1, 1}}};
SpringKind kind_of_offset(const std::array<int, 3>& offset);

// Cells of the box containing the spring from node (ix, iy, iz) to its neighbour at `offset`
// (both must be in the box): 1-4 for an edge, 1-2 for a face diagonal, 1 for a body diagonal.
int cells_containing(const GridShape& shape, int ix, int iy, int iz,
                     const std::array<int, 3>& offset);
// The same number for a spring deep inside the box: 4, 2, 1.
int bulk_cells_containing(SpringKind kind);

// Which springs count as particle springs (Section 4.2.2).
enum class ParticleSpringRule {
  same_particle,  // both ends are nodes of the same particle (the text)
  any_particle,   // both ends are particle nodes, of any particles (the original code)
};

// Each spring's stiffness (N/m), kind, whether it got the particle constant, and the index
// step from its first node to its second, as a one-byte index into a table of the lattice's
// distinct combinations: a lattice has at most 38 of them (13 forward offsets; per edge offset
// the weights 1/4, 1/2, 1 of the bulk constant and the particle constant, per face-diagonal
// offset 1/2, 1 and the particle's, per body diagonal 1 and the particle's), so this keeps
// 1 byte per spring instead of 14 (about 160 bytes per node) and gives back the same values bit
// for bit.
class SpringProperties {
 public:
  struct Entry {
    double stiffness = 0.0;  // N/m
    // second - first: the node index step of the spring's forward offset on this grid.
    std::int32_t index_step = 0;
    SpringKind kind = SpringKind::edge;
    bool particle = false;
    bool operator==(const Entry&) const = default;
  };

  const Entry& operator[](std::size_t s) const { return table_[index_[s]]; }
  // Spring s's entry as an index into table().
  std::uint8_t table_index(std::size_t s) const { return index_[s]; }
  std::size_t size() const { return index_.size(); }
  void reserve(std::size_t n) { index_.reserve(n); }
  // Appends a spring. Throws std::length_error past 256 distinct entries.
  void push_back(const Entry& entry);
  const std::vector<Entry>& table() const { return table_; }

 private:
  std::vector<Entry> table_;
  std::vector<std::uint8_t> index_;
};

// Springs as parallel arrays (structure of arrays): the first node of each spring, and its
// properties byte, which also gives the second node: first(s) < second(s).
struct SpringSet {
  std::vector<std::int32_t> first;
  SpringProperties properties;
  double element_length = 0.0;  // m

  std::size_t size() const { return first.size(); }
  std::int32_t second(std::size_t s) const { return first[s] + properties[s].index_step; }
  double stiffness(std::size_t s) const { return properties[s].stiffness; }  // N/m
  SpringKind kind(std::size_t s) const { return properties[s].kind; }
  // True if the spring got the particle constant.
  bool particle(std::size_t s) const { return properties[s].particle; }
  double rest_length(std::size_t s) const { return element_length * rest_length_factor(kind(s)); }
};

// All springs of the box. particle_of_node[n] is the particle holding node n, or -1 (may be
// empty: no particles). Springs come in node-index order, each node's in kForwardNeighbours
// order.
SpringSet build_springs(const GridShape& shape, double element_length,
                        const SpringConstants& polymer, const SpringConstants& particle,
                        const std::vector<std::int32_t>& particle_of_node, ParticleSpringRule rule);

// Closed forms for a box without particles (docs/original-code.md#springs), per kind: how many
// springs carry 1/4, 1/2 and all of the bulk constant.
struct SpringCountsOfKind {
  std::int64_t quarter = 0;
  std::int64_t half = 0;
  std::int64_t full = 0;
  std::int64_t total() const { return quarter + half + full; }
};
struct SpringCounts {
  SpringCountsOfKind edge;
  SpringCountsOfKind face;
  SpringCountsOfKind body;
  std::int64_t total() const { return edge.total() + face.total() + body.total(); }
};
SpringCounts closed_form_spring_counts(const GridShape& shape);

}  // namespace mresim::lattice
