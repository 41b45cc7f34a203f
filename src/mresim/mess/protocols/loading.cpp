#include "mresim/mess/protocols/loading.hpp"

#include <fmt/format.h>

#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

// Boundary conditions of the 3D protocols, transcribed from the original code's rules
// (docs/original-code.md#boundary-conditions; Section 4.2.7). Notes on what the header leaves open:
//  - "Held at `reference`" writes the reference's columns into `prescribed`; coordinates that
//    are not held keep `prescribed` at zero (BoundaryConstraints ignores them).
//  - Simple shear (eq. 4.96): u_direction = tan(gamma) h with h the node's *reference*
//    coordinate along the normal, so the lower face (h = 0 in the initial lattice) stays put
//    and the upper face moves by tan(gamma) L.
//  - Torsion turns the upper face about the box's axis (the line through (L_a/2, L_b/2) of the
//    initial lattice, a and b the other two axes); the original turns about (Nel_x/2, Nel_y/2)
//    too (without its CW offset bug). The face's coordinate along the normal is not changed.
//  - Stress areas are those of the initial box, (N_a - 1) l_e (N_b - 1) l_e.
//  - measured_strain measures the upper face *relative to the lower face* of `normal`. With the
//    lower face held (one_face) this is the header's "upper face relative to reference"; with
//    both faces loaded the lower face moves too and only the difference is a strain. For shear
//    with both_faces the load is pure shear (tractions on both face pairs), whose deformation is
//    symmetric: the faces normal to `normal` slide by only half of the engineering shear; the
//    other half is the faces normal to `direction` sliding along `normal`. The returned angle is
//    then the decrease of the right angle between the two material lines, atan(a) + atan(b)
//    (a, b the two relative slides over their heights), which is gamma for simple shear (b = 0)
//    and for pure shear, and is unchanged by a small rigid rotation of the free body.

namespace mresim::mess_protocol {

namespace {

using lattice::Face;
using mess_config::LoadKind;

Face lower_face(int axis) {
  return axis == 0 ? Face::left : axis == 1 ? Face::front : Face::bottom;
}

Face upper_face(int axis) { return axis == 0 ? Face::right : axis == 1 ? Face::back : Face::top; }

void check_axis(const char* function, const char* name, int axis) {
  if (axis < 0 || axis > 2) {
    throw std::invalid_argument(
        fmt::format("{}: {} = {} is not an axis (0 = x, 1 = y, 2 = z)", function, name, axis));
  }
}

// Axes of a load; shear needs a direction other than the normal. Returns the axis the load
// acts along (direction for shear, normal otherwise).
int load_axis(const char* function, LoadKind kind, int normal, int direction) {
  check_axis(function, "normal", normal);
  if (kind != LoadKind::shear) return normal;
  check_axis(function, "direction", direction);
  if (direction == normal) {
    throw std::invalid_argument(fmt::format(
        "{}: shear direction = {} equals normal = {}; it must be one of the other two axes",
        function, direction, normal));
  }
  return direction;
}

void check_positions(const char* function, const char* name, const lattice::Lattice& lattice,
                     const Eigen::Matrix3Xd& x) {
  if (x.cols() != lattice.node_count()) {
    throw std::invalid_argument(fmt::format("{}: {} has {} columns, the lattice {} nodes", function,
                                            name, x.cols(), lattice.node_count()));
  }
}

void check_finite(const char* function, const char* name, double value) {
  if (!std::isfinite(value)) {
    throw std::invalid_argument(fmt::format("{}: {} = {} is not finite", function, name, value));
  }
}

// Tension values are positive and compression values negative (StrainSpec / StressSpec store
// compression negative, the original forces the signs); anything else is a caller's sign slip.
void check_sign(const char* function, LoadKind kind, double value) {
  if (kind == LoadKind::tension && value < 0.0) {
    throw std::invalid_argument(fmt::format(
        "{}: tension value = {} is negative; compression is its own kind (stored negative)",
        function, value));
  }
  if (kind == LoadKind::compression && value > 0.0) {
    throw std::invalid_argument(fmt::format(
        "{}: compression value = {} is positive; compression values are stored negative", function,
        value));
  }
}

// Nodes on any of the six faces, each once, in increasing index order.
std::vector<int> surface_nodes(const lattice::GridShape& shape) {
  std::vector<int> out;
  for (int n = 0; n < static_cast<int>(shape.node_count()); ++n) {
    const std::array<int, 3> c = shape.node_coordinates(n);
    for (int a = 0; a < 3; ++a) {
      if (c[a] == 0 || c[a] == shape.nodes[a] - 1) {
        out.push_back(n);
        break;
      }
    }
  }
  return out;
}

// Reference position of `node` moved by the affine simple-shear field x_d += tan(gamma) x_n
// (eq. 4.96, docs/original-code.md#boundary-conditions).
Eigen::Vector3d sheared(const Eigen::Matrix3Xd& reference, int node, int normal, int direction,
                        double tan_gamma) {
  Eigen::Vector3d p = reference.col(node);
  p[direction] += tan_gamma * reference(normal, node);
  return p;
}

// Mean over `nodes` of coordinate `axis` of x, or of the displacement x - *base if base is
// given.
double face_mean(const std::vector<int>& nodes, const Eigen::Matrix3Xd& x, int axis,
                 const Eigen::Matrix3Xd* base = nullptr) {
  double sum = 0.0;
  for (const int n : nodes) sum += x(axis, n) - (base != nullptr ? (*base)(axis, n) : 0.0);
  return sum / static_cast<double>(nodes.size());
}

// Relative slide along `along` of the upper face of `axis` against its lower face, over the
// reference distance between the two faces.
double relative_slide(const lattice::GridShape& shape, int axis, int along,
                      const Eigen::Matrix3Xd& positions, const Eigen::Matrix3Xd& reference) {
  const std::vector<int> lower = lattice::face_nodes(shape, lower_face(axis));
  const std::vector<int> upper = lattice::face_nodes(shape, upper_face(axis));
  const double height = face_mean(upper, reference, axis) - face_mean(lower, reference, axis);
  const double slide = face_mean(upper, positions, along, &reference) -
                       face_mean(lower, positions, along, &reference);
  return slide / height;
}

}  // namespace

LoadState hysteresis_load(const lattice::Lattice& lattice, const Eigen::Matrix3Xd& reference) {
  check_positions("hysteresis_load", "reference", lattice, reference);
  LoadState s;
  s.constraints = mess::BoundaryConstraints::none(lattice.node_count());
  for (const Face f : {Face::left, Face::right, Face::front, Face::back, Face::bottom, Face::top}) {
    s.constraints.fix_face(lattice.shape, f, reference);
  }
  return s;
}

LoadState magnetostriction_load(const lattice::Lattice& lattice,
                                const Eigen::Matrix3Xd& reference) {
  check_positions("magnetostriction_load", "reference", lattice, reference);
  LoadState s;
  s.constraints = mess::BoundaryConstraints::none(lattice.node_count());
  s.constraints.fix_face(lattice.shape, Face::bottom, reference);
  return s;
}

LoadState strain_load(const lattice::Lattice& lattice, const mess_config::StrainSpec& strain,
                      double value, const Eigen::Matrix3Xd& reference) {
  constexpr const char* kFn = "strain_load";
  const int normal = strain.normal;
  const int along = load_axis(kFn, strain.kind, normal, strain.direction);
  check_positions(kFn, "reference", lattice, reference);
  check_finite(kFn, "value", value);
  check_sign(kFn, strain.kind, value);
  if ((strain.kind == LoadKind::tension || strain.kind == LoadKind::compression) &&
      std::abs(value) >= 1.0) {
    throw std::invalid_argument(fmt::format(
        "{}: {} strain value = {} is not allowed: |strain| must be below 1 (at -1 the upper "
        "face would reach the lower one)",
        kFn, mess_config::to_string(strain.kind), value));
  }
  if (strain.kind == LoadKind::shear && std::abs(value) >= std::numbers::pi / 2.0) {
    throw std::invalid_argument(fmt::format(
        "{}: shear angle value = {} rad is not allowed: |gamma| must be below pi/2 (u = h "
        "tan(gamma))",
        kFn, value));
  }

  const lattice::GridShape& shape = lattice.shape;
  LoadState s;
  s.constraints = mess::BoundaryConstraints::none(lattice.node_count());
  mess::BoundaryConstraints& c = s.constraints;
  const std::vector<int> lower = lattice::face_nodes(shape, lower_face(normal));
  const std::vector<int> upper = lattice::face_nodes(shape, upper_face(normal));

  // strain_simple_shearing: the whole boundary on the affine field, at every value (0 too).
  if (strain.kind == LoadKind::shear && strain.boundary == mess_config::ShearBoundary::all_faces) {
    const double t = std::tan(value);
    for (const int n : surface_nodes(shape)) c.hold(n, sheared(reference, n, normal, along, t));
    return s;
  }

  // Zero strain (tension, compression, torsion, shear on the normal faces): the lower face
  // held, the upper one a rigid body, so the state relaxes (magnetostricts) freely along the
  // load and becomes the reference of the nonzero strains (the original, not the text:
  // docs/original-code.md#boundary-conditions).
  if (value == 0.0) {
    c.fix_nodes(lower, reference);
    c.add_rigid_group(std::vector<std::int32_t>(upper.begin(), upper.end()));
    return s;
  }

  switch (strain.kind) {
    case LoadKind::shear: {  // strain_shearing: both normal faces on the affine field
      const double t = std::tan(value);
      for (const int n : lower) c.hold(n, sheared(reference, n, normal, along, t));
      for (const int n : upper) c.hold(n, sheared(reference, n, normal, along, t));
      break;
    }
    case LoadKind::tension:
    case LoadKind::compression: {  // upper face's normal coordinate scaled by (1 + strain)
      c.fix_nodes(lower, reference);
      for (const int n : upper) {
        Eigen::Vector3d p = reference.col(n);
        p[normal] *= 1.0 + value;
        c.hold(n, p);
      }
      break;
    }
    case LoadKind::torsion: {  // upper face turned about the box's axis along `normal`
      c.fix_nodes(lower, reference);
      Eigen::Vector3d centre = 0.5 * lattice.box_lengths();
      const Eigen::Matrix3d rotation =
          Eigen::AngleAxisd(value, Eigen::Vector3d::Unit(normal)).toRotationMatrix();
      for (const int n : upper) {
        const Eigen::Vector3d p = reference.col(n);
        centre[normal] = p[normal];  // rotate within the face's own plane
        c.hold(n, centre + rotation * (p - centre));
      }
      break;
    }
  }
  return s;
}

LoadState stress_load(const lattice::Lattice& lattice, const mess_config::StressSpec& stress,
                      double value, const Eigen::Matrix3Xd& reference) {
  constexpr const char* kFn = "stress_load";
  const int normal = stress.normal;
  if (stress.kind == LoadKind::torsion) {
    throw std::invalid_argument(fmt::format("{}: kind = torsion has no stress form", kFn));
  }
  const int along = load_axis(kFn, stress.kind, normal, stress.direction);
  check_positions(kFn, "reference", lattice, reference);
  check_finite(kFn, "value", value);
  check_sign(kFn, stress.kind, value);

  const lattice::GridShape& shape = lattice.shape;
  const Eigen::Vector3d L = lattice.box_lengths();
  // Initial area of the faces normal to `axis`, and the force on each of their nodes: the
  // original gives every node the same share, edges and corners included
  // (docs/original-code.md#boundary-conditions).
  const auto per_node = [&](int axis, std::size_t nodes) {
    return value * (L.prod() / L[axis]) / static_cast<double>(nodes);
  };

  LoadState s;
  s.constraints = mess::BoundaryConstraints::none(lattice.node_count());
  s.applied_forces = Eigen::Matrix3Xd::Zero(3, lattice.node_count());
  const std::vector<int> lower = lattice::face_nodes(shape, lower_face(normal));
  const std::vector<int> upper = lattice::face_nodes(shape, upper_face(normal));
  const double f = per_node(normal, upper.size());
  for (const int n : upper) s.applied_forces(along, n) += f;

  if (stress.loading == mess_config::StressLoading::one_face) {
    s.constraints.fix_nodes(lower, reference);
    return s;
  }
  // both_faces: equal and opposite tractions, so no net force; for shear the complementary
  // pair on the faces normal to `direction` (along `normal`, stress x their own area) cancels
  // the couple of the first pair: L_n (value A_n) = L_d (value A_d) = value V.
  for (const int n : lower) s.applied_forces(along, n) -= f;
  if (stress.kind == LoadKind::shear) {
    const std::vector<int> lower_d = lattice::face_nodes(shape, lower_face(along));
    const std::vector<int> upper_d = lattice::face_nodes(shape, upper_face(along));
    const double f_d = per_node(along, upper_d.size());
    for (const int n : upper_d) s.applied_forces(normal, n) += f_d;
    for (const int n : lower_d) s.applied_forces(normal, n) -= f_d;
  }
  return s;
}

double measured_strain(const lattice::Lattice& lattice, const mess_config::StressSpec& stress,
                       const Eigen::Matrix3Xd& positions, const Eigen::Matrix3Xd& reference) {
  constexpr const char* kFn = "measured_strain";
  if (stress.kind == LoadKind::torsion) {
    throw std::invalid_argument(fmt::format("{}: kind = torsion has no stress form", kFn));
  }
  const int normal = stress.normal;
  const int along = load_axis(kFn, stress.kind, normal, stress.direction);
  check_positions(kFn, "positions", lattice, positions);
  check_positions(kFn, "reference", lattice, reference);
  const lattice::GridShape& shape = lattice.shape;
  const double a = relative_slide(shape, normal, along, positions, reference);
  if (stress.kind != LoadKind::shear) return a;  // engineering strain along the normal
  if (stress.loading == mess_config::StressLoading::one_face) return std::atan(a);
  // Pure shear: the slide of the `along` faces in the normal direction (the roles swap).
  // NOLINTNEXTLINE(readability-suspicious-call-argument)
  const double b = relative_slide(shape, along, normal, positions, reference);
  return std::atan(a) + std::atan(b);
}

}  // namespace mresim::mess_protocol
