#pragma once

// Boundary constraints of the 3D model (docs/original-code.md#boundary-conditions) and the map
// between node positions and the free variables the minimisers work on.
//
// Two kinds of constraint, enough for every boundary condition of the original code:
//  - fixed coordinates: coordinate a of node n is held at prescribed(a, n) (fixed surfaces,
//    displaced surfaces of strain runs: the caller holds them at the displaced positions);
//  - rigid groups: the nodes of a group move together by one common translation (all three
//    components), e.g. the loaded face of tension/compression/shear runs at zero strain, which
//    floats as a rigid body in the original. Group nodes must not have fixed coordinates.
// Everything else is free. Particle nodes are normally free (particles never touch the box).

#include <Eigen/Core>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "mresim/mess/lattice/grid.hpp"

namespace mresim::mess {

struct RigidGroup {
  std::vector<std::int32_t> nodes;
};

struct BoundaryConstraints {
  // fixed[3 n + a] != 0: coordinate a (0 = x, 1 = y, 2 = z) of node n is held. Empty = none.
  std::vector<std::uint8_t> fixed;
  std::vector<RigidGroup> rigid_groups;

  // No constraints for N nodes.
  static BoundaryConstraints none(std::int64_t node_count);

  bool is_fixed(std::int64_t node, int axis) const {
    return !fixed.empty() && fixed[static_cast<std::size_t>(3 * node + axis)] != 0;
  }
  // Holds coordinate `axis` of `node` at `value` (m), or all three at `position`. `fixed` must
  // have its 3 N entries (none()).
  void hold(std::int64_t node, int axis, double value);
  void hold(std::int64_t node, const Eigen::Vector3d& position);
  // The value a held coordinate is held at (m); 0 for one that was marked in `fixed` only.
  double prescribed(int axis, std::int64_t node) const;
  // Holds all three coordinates of `nodes` at `positions` (columns of those nodes).
  void fix_nodes(const std::vector<int>& nodes, const Eigen::Matrix3Xd& positions);
  // Holds all three coordinates of the nodes of one face of the box at `positions`.
  void fix_face(const lattice::GridShape& shape, lattice::Face face,
                const Eigen::Matrix3Xd& positions);
  void add_rigid_group(std::vector<std::int32_t> nodes);

  // Throws std::invalid_argument for wrong sizes, node indices out of range, a node in two
  // groups or a group node with a held coordinate.
  void validate(std::int64_t node_count) const;

  // Writes the held coordinates into x.
  void apply(Eigen::Matrix3Xd& x) const;

 private:
  // The held nodes' values, by node: held coordinates lie on the box's faces, so a map keeps
  // them in a few bytes per node of the box instead of a 3 x N array (24 bytes per node).
  std::unordered_map<std::int32_t, Eigen::Vector3d> prescribed_;
};

// Free variables in units of a length scale (l_e): every free coordinate of a node outside the
// rigid groups, then 3 translation components per rigid group (relative to the group's
// positions when the map was built). Gradients map accordingly (dE/du = l_e dE/dx; a group's
// component is the sum over its nodes).
class DofMap {
 public:
  DofMap(const BoundaryConstraints& constraints, const Eigen::Matrix3Xd& reference,
         double length_scale);

  Eigen::Index size() const {
    return static_cast<Eigen::Index>(coordinates_.size()) + 3 * groups();
  }
  Eigen::Index groups() const { return static_cast<Eigen::Index>(group_nodes_.size()); }
  double length_scale() const { return length_scale_; }

  // u from positions (the groups' translations from their first node).
  Eigen::VectorXd to_dofs(const Eigen::Matrix3Xd& x) const;
  // Writes the free coordinates and group nodes of x from u; held coordinates are left as
  // they are in x.
  void to_positions(const Eigen::VectorXd& u, Eigen::Matrix3Xd& x) const;
  // The same for u + alpha d, without forming that vector (bitwise the same positions).
  void to_positions(const Eigen::VectorXd& u, double alpha, const Eigen::VectorXd& d,
                    Eigen::Matrix3Xd& x) const;
  // dE/du from dE/dx (3 x N).
  Eigen::VectorXd reduce(const Eigen::Matrix3Xd& gradient) const;
  // out = reduce(gradient) / divisor and max_k |reduce(gradient)_k / divisor|, bitwise the
  // same, without a temporary (at full size each dof vector is 24 bytes per node).
  void reduce_divided(const Eigen::Matrix3Xd& gradient, double divisor, Eigen::VectorXd& out) const;
  double max_abs_reduced_divided(const Eigen::Matrix3Xd& gradient, double divisor) const;
  // The node direction (3 x N, units of l_e) that a change v of the dofs makes: free
  // coordinates take their dof, group nodes their group's translation, held coordinates 0.
  // reduce() is its transpose (times l_e).
  Eigen::Matrix3Xd expand(const Eigen::VectorXd& v) const;
  // Per coordinate 3 n + a: 1 if it is a dof of its own (free and outside every group).
  std::vector<std::uint8_t> own_dof_mask() const;
  // The flat coordinate 3 n + a of dof k, for k < size() - 3 groups().
  std::int64_t coordinate_of(Eigen::Index k) const {
    return coordinates_[static_cast<std::size_t>(k)];
  }
  Eigen::Index own_dofs() const { return static_cast<Eigen::Index>(coordinates_.size()); }
  const std::vector<std::int32_t>& group_nodes(Eigen::Index g) const {
    return group_nodes_[static_cast<std::size_t>(g)];
  }
  // Masses per dof from nodal masses (a group's is the sum of its nodes').
  Eigen::VectorXd reduce_masses(const Eigen::VectorXd& masses) const;
  // The dof that moves coordinate a of node n: its own, its rigid group's translation
  // component, or -1 if the coordinate is held.
  Eigen::Index dof_of(std::int64_t node, int axis) const {
    return dof_index_[static_cast<std::size_t>(3 * node + axis)];
  }
  // Whether dof k is a rigid group's translation component.
  // The own dof of flat coordinate c = 3 n + a, or -1 (held, or a node of a rigid group).
  Eigen::Index own_dof_of_coordinate(std::int64_t c) const {
    const std::int32_t k = dof_index_[static_cast<std::size_t>(c)];
    return k < static_cast<std::int32_t>(coordinates_.size()) ? k : -1;
  }
  bool is_group_dof(Eigen::Index k) const {
    return k >= static_cast<Eigen::Index>(coordinates_.size());
  }

 private:
  template <class Dofs>
  void write_positions(const Dofs& u, Eigen::Matrix3Xd& x) const;
  // visit(k, dE/du_k) for every dof in order.
  template <class Visit>
  void for_each_reduced(const Eigen::Matrix3Xd& gradient, Visit&& visit) const;

  double length_scale_ = 1.0;
  // 32-bit indices (the constructor checks that 3 N fits): 24 bytes per node less than 64-bit.
  std::vector<std::int32_t> coordinates_;  // flat index 3 n + a of each free coordinate
  std::vector<std::vector<std::int32_t>> group_nodes_;
  std::vector<Eigen::Matrix3Xd> group_reference_;  // positions of each group's nodes
  std::vector<std::int32_t> dof_index_;            // per flat coordinate 3 n + a, -1 if held
};

}  // namespace mresim::mess
