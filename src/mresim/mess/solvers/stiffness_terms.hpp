#pragma once

// The elastic stiffness that L-BFGS's preconditioners approximate (preconditioner.hpp,
// multilevel_correction.hpp), as rank-one terms linearised at a state of the lattice:
//
//   spring s (stiffness k, rest length L) between nodes i and j, l = |x_j - x_i|,
//   u = (x_j - x_i)/l:   c u u^T on x_j - x_i,  c = k L / l;
//   cell (8 vertices):   c g g^T,  g = dV/dx at x (eqs. 4.66-4.69 with the 1/4),
//                        c = force_factor kappa / V0.
//
// These are the springs' and cells' Hessians (elastic_terms.hpp) without the parts that change
// sign: the spring's k (1 - L/l) I (negative where the spring is compressed) and the cell's
// kappa (V/V0 - 1) d^2V/dx^2. So every term is positive semi-definite, and at rest (l = L,
// V = V0) they are the exact Hessians: k e e^T with e the rest direction, and g_a = +-l_e^2/4.
//
// Why a state other than the reference lattice. In contact the polymer between two particles
// is compressed and sheared far from its rest shape, and a preconditioner built from the rest
// lattice describes it badly: on the full-size Fig. 4.11 loop a step in contact took 701
// L-BFGS iterations with it and 447 with one built at the step's starting state
// (docs/performance.md, "Preconditioner at the starting state").
//
// Springs and cells with a node that has a held coordinate are taken at rest whatever the
// state: a strain step starts with its held faces already moved to their new positions while
// the nodes next to them have not followed, a one-layer transient that the relaxation removes
// in its first iterations, and a preconditioner built for it is a bad one (measured: a 1 %
// shear step of the scaled-down helix took 1,498 iterations instead of 261).

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cstdint>
#include <utility>

#include "mresim/mess/lattice/lattice.hpp"
#include "mresim/mess/lattice/volume_elements.hpp"
#include "mresim/mess/system/constraints.hpp"

namespace mresim::mess {

// Calls spring(i, j, u, c) for every spring and cell(element, g, c) for every cell with a node in
// the lattice layers z_first ... z_last along z (the fastest axis of the node numbering, the
// slowest of the cells'), and maybe some more next to them; springs in index order, then cells
// in index order, with the terms of the header linearised at `state` (3 x N positions, m), or at
// rest where `state` is null. `map` tells which coordinates are held. `scale` multiplies every c
// (the preconditioners' variables are scaled: l_e / force_scale). Springs come in the order of
// their first node and join it to a forward neighbour at most one layer away, and cells span
// two layers: so the band's springs are one range per z-line of nodes, its cells one range.
template <class Spring, class Cell>
void for_each_stiffness_term_in_layers(const lattice::Lattice& lattice,
                                       const Eigen::Matrix3Xd* state, const DofMap& map,
                                       double volume_force_factor, double scale, int z_first,
                                       int z_last, Spring&& spring, Cell&& cell) {
  const Eigen::Matrix3Xd& x0 = lattice.positions;
  const double l_e = lattice.element_length;
  const auto has_held_coordinate = [&map](std::int64_t n) {
    return map.dof_of(n, 0) < 0 || map.dof_of(n, 1) < 0 || map.dof_of(n, 2) < 0;
  };
  const lattice::GridShape& shape = lattice.shape;
  const std::array<int, 3> cells = shape.cells();
  const int nz = shape.nodes[2];
  const int layer_first = std::max(z_first - 1, 0);
  const int layer_last = std::min(z_last + 1, nz - 1);
  const lattice::SpringSet& sp = lattice.springs;
  const auto add_spring = [&](std::size_t s) {
    const std::int64_t i = sp.first[s];
    const std::int64_t j = sp.second(s);
    if (state == nullptr || has_held_coordinate(i) || has_held_coordinate(j)) {
      spring(i, j, Eigen::Vector3d((x0.col(j) - x0.col(i)).normalized()), sp.stiffness(s) * scale);
      return;
    }
    const Eigen::Vector3d r = state->col(j) - state->col(i);
    const double l = r.norm();
    spring(i, j, Eigen::Vector3d(r / l), sp.stiffness(s) * sp.rest_length(s) / l * scale);
  };
  if (layer_first == 0 && layer_last == nz - 1) {
    for (std::size_t s = 0; s < sp.size(); ++s) add_spring(s);
  } else {
    const std::int64_t lines = std::int64_t{shape.nodes[0]} * shape.nodes[1];
    auto from = sp.first.begin();
    for (std::int64_t line = 0; line < lines; ++line) {
      from = std::lower_bound(from, sp.first.end(), line * nz + layer_first);
      const auto to = std::lower_bound(from, sp.first.end(), line * nz + layer_last + 1);
      for (auto it = from; it != to; ++it) {
        add_spring(static_cast<std::size_t>(it - sp.first.begin()));
      }
      from = to;
    }
  }
  const double c =
      volume_force_factor * std::abs(lattice.polymer.kappa) / (l_e * l_e * l_e) * scale;
  lattice::CellVertices vertices;
  lattice::CellVertices g;
  const auto add_cell = [&](const lattice::GridCells::Cell& element) {
    bool at_rest = state == nullptr;
    for (std::size_t v = 0; v < 8 && !at_rest; ++v) at_rest = has_held_coordinate(element[v]);
    if (at_rest) {
      Eigen::Vector3d centre = Eigen::Vector3d::Zero();
      for (const std::int32_t n : element) centre += x0.col(n);
      centre /= 8.0;
      for (std::size_t v = 0; v < 8; ++v) {
        g[v] = (x0.col(element[v]) - centre).cwiseSign() * (l_e * l_e / 4.0);
      }
    } else {
      for (std::size_t v = 0; v < 8; ++v) vertices[v] = state->col(element[v]);
      (void)lattice::cell_volume_and_gradient(vertices, g);
    }
    cell(element, g, c);
  };
  if (lattice.elements.empty()) return;
  // Cell index cx + Cx (cy + Cy cz) (volume_elements.hpp): the band's cells are contiguous.
  const std::size_t layer = static_cast<std::size_t>(cells[0]) * cells[1];
  const std::size_t begin = layer * static_cast<std::size_t>(std::max(z_first - 1, 0));
  const std::size_t end = layer * static_cast<std::size_t>(std::min(z_last, cells[2] - 1) + 1);
  for (std::size_t e = begin; e < end; ++e) add_cell(lattice.elements[e]);
}

// Every spring and cell, in index order (for_each_stiffness_term_in_layers over all layers).
template <class Spring, class Cell>
void for_each_stiffness_term(const lattice::Lattice& lattice, const Eigen::Matrix3Xd* state,
                             const DofMap& map, double volume_force_factor, double scale,
                             Spring&& spring, Cell&& cell) {
  for_each_stiffness_term_in_layers(lattice, state, map, volume_force_factor, scale, 0,
                                    lattice.shape.nodes[2] - 1, std::forward<Spring>(spring),
                                    std::forward<Cell>(cell));
}

}  // namespace mresim::mess
