// Tests of the 3D protocols' boundary conditions (loading.hpp;
// docs/original-code.md#boundary-conditions):
//  - which coordinates each protocol holds, at which values, which faces float as rigid bodies
//    and which nodal forces a stress applies; non-cubic boxes and normals other than z, so that
//    mixed-up axes fail;
//  - physics on a particle-free block in the physical profile: free uniaxial tension (only the
//    loaded faces' normal coordinates held) recovers the input E and nu, the protocol's clamped
//    tension is stiffer by a measured amount, and simple shear gives G gamma^2/2;
//  - measured_strain of affinely displaced configurations.

#include "mresim/mess/protocols/loading.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <limits>
#include <set>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "../support/mess_test_support.hpp"
#include "mresim/mess/solvers/minimiser.hpp"

namespace mess = mresim::mess;
namespace lat = mresim::lattice;
namespace cfg = mresim::mess_config;
namespace mp = mresim::mess_protocol;
using mess::testing::perturbed;
using mess::testing::small_lattice;

namespace {

// 5 x 6 x 7 nodes (4 x 5 x 6 cells), no particles, l_e = 1 um (n_d = 1, R = 1.5 um).
lat::Lattice block(double poisson_ratio = 0.47) {
  return small_lattice(mess::model_profile("physical"), {4, 5, 6}, {}, 1, poisson_ratio);
}

// A reference that is not the initial lattice, so that "held at reference" is checked for real.
Eigen::Matrix3Xd shifted_reference(const lat::Lattice& l) {
  return perturbed(l.positions, 0.05 * l.element_length);
}

// Grid coordinate of `node` along `axis` is 0 (lower) or N - 1 (upper).
bool on_face(const lat::GridShape& shape, int node, int axis, bool upper) {
  const int c = shape.node_coordinates(node)[axis];
  return c == (upper ? shape.nodes[axis] - 1 : 0);
}

bool on_surface(const lat::GridShape& shape, int node) {
  for (int a = 0; a < 3; ++a) {
    if (on_face(shape, node, a, false) || on_face(shape, node, a, true)) return true;
  }
  return false;
}

int held_coordinates(const mess::BoundaryConstraints& c, int node) {
  int k = 0;
  for (int a = 0; a < 3; ++a) k += c.is_fixed(node, a) ? 1 : 0;
  return k;
}

// Expects every coordinate of `node` held at `expected` (to rounding of the arithmetic).
void expect_held_at(const mess::BoundaryConstraints& c, int node, const Eigen::Vector3d& expected,
                    double tolerance = 1e-18) {
  for (int a = 0; a < 3; ++a) {
    ASSERT_TRUE(c.is_fixed(node, a)) << "node " << node << " axis " << a;
    EXPECT_NEAR(c.prescribed(a, node), expected[a], tolerance) << "node " << node << " axis " << a;
  }
}

cfg::StrainSpec strain_spec(cfg::LoadKind kind, int normal, int direction,
                            cfg::ShearBoundary boundary = cfg::ShearBoundary::all_faces) {
  cfg::StrainSpec s;
  s.kind = kind;
  s.normal = normal;
  s.direction = direction;
  s.boundary = boundary;
  return s;
}

cfg::StressSpec stress_spec(cfg::LoadKind kind, int normal, int direction,
                            cfg::StressLoading loading) {
  cfg::StressSpec s;
  s.kind = kind;
  s.normal = normal;
  s.direction = direction;
  s.loading = loading;
  return s;
}

// Tight relaxation: forces below 1e-12 F0 so that displacements are converged far below the
// 1e-6 relative accuracy asserted on the moduli.
mess::MinimiserResult relax(mess::MessSystem& sys) {
  mess::MinimiserOptions opt;
  opt.force_tolerance = 1e-12;
  return mess::minimise(sys, opt);
}

}  // namespace

// ------------------------------------------------------------------- which coordinates are held

TEST(Loading, HysteresisHoldsAllSixFacesAtTheReference) {
  const lat::Lattice l = block();
  const Eigen::Matrix3Xd ref = shifted_reference(l);
  const mp::LoadState s = mp::hysteresis_load(l, ref);
  EXPECT_EQ(s.applied_forces.size(), 0);
  EXPECT_TRUE(s.constraints.rigid_groups.empty());
  int held = 0;
  for (int n = 0; n < l.node_count(); ++n) {
    if (on_surface(l.shape, n)) {
      expect_held_at(s.constraints, n, ref.col(n), 0.0);
      ++held;
    } else {
      EXPECT_EQ(held_coordinates(s.constraints, n), 0) << "interior node " << n;
    }
  }
  EXPECT_EQ(held, 5 * 6 * 7 - 3 * 4 * 5);
  EXPECT_NO_THROW(s.constraints.validate(l.node_count()));
}

TEST(Loading, MagnetostrictionHoldsOnlyTheBottomFace) {
  const lat::Lattice l = block();
  const Eigen::Matrix3Xd ref = shifted_reference(l);
  const mp::LoadState s = mp::magnetostriction_load(l, ref);
  EXPECT_EQ(s.applied_forces.size(), 0);
  EXPECT_TRUE(s.constraints.rigid_groups.empty());
  for (int n = 0; n < l.node_count(); ++n) {
    if (on_face(l.shape, n, 2, false)) {
      expect_held_at(s.constraints, n, ref.col(n), 0.0);
    } else {
      EXPECT_EQ(held_coordinates(s.constraints, n), 0) << "node " << n;
    }
  }
}

// Value 0 of tension, compression, torsion and shear on the normal faces: lower face of the
// normal held, the upper face one rigid group, nothing else constrained.
TEST(Loading, ZeroStrainHoldsTheLowerFaceAndFloatsTheUpperFace) {
  const lat::Lattice l = block();
  const Eigen::Matrix3Xd ref = shifted_reference(l);
  const std::vector<cfg::StrainSpec> specs = {
      strain_spec(cfg::LoadKind::tension, 0, 0),
      strain_spec(cfg::LoadKind::compression, 1, 1),
      strain_spec(cfg::LoadKind::torsion, 2, 2),
      strain_spec(cfg::LoadKind::shear, 1, 2, cfg::ShearBoundary::normal_faces),
  };
  for (const cfg::StrainSpec& spec : specs) {
    SCOPED_TRACE(cfg::to_string(spec.kind) + " normal " + std::to_string(spec.normal));
    const mp::LoadState s = mp::strain_load(l, spec, 0.0, ref);
    EXPECT_EQ(s.applied_forces.size(), 0);
    ASSERT_EQ(s.constraints.rigid_groups.size(), 1u);
    const std::set<int> group(s.constraints.rigid_groups[0].nodes.begin(),
                              s.constraints.rigid_groups[0].nodes.end());
    const int face_size = static_cast<int>(l.node_count()) / l.shape.nodes[spec.normal];
    EXPECT_EQ(static_cast<int>(group.size()), face_size);
    for (int n = 0; n < l.node_count(); ++n) {
      if (on_face(l.shape, n, spec.normal, false)) {
        expect_held_at(s.constraints, n, ref.col(n), 0.0);
      } else {
        EXPECT_EQ(held_coordinates(s.constraints, n), 0) << "node " << n;
        EXPECT_EQ(group.count(n), on_face(l.shape, n, spec.normal, true) ? 1u : 0u) << "node " << n;
      }
    }
    EXPECT_NO_THROW(s.constraints.validate(l.node_count()));
  }
}

// strain_simple_shearing (eq. 4.96): every surface node on x_d = ref_d + tan(gamma) ref_n, the
// interior free; also at gamma = 0 (all faces held at the reference).
TEST(Loading, SimpleShearHoldsEverySurfaceNodeOnTheAffineField) {
  const lat::Lattice l = block();
  const Eigen::Matrix3Xd ref = shifted_reference(l);
  for (const auto& [normal, direction] : {std::pair{0, 1}, std::pair{2, 0}, std::pair{1, 2}}) {
    for (const double gamma : {0.0, 0.1, -0.3}) {
      SCOPED_TRACE("normal " + std::to_string(normal) + " direction " + std::to_string(direction) +
                   " gamma " + std::to_string(gamma));
      const mp::LoadState s =
          mp::strain_load(l, strain_spec(cfg::LoadKind::shear, normal, direction), gamma, ref);
      EXPECT_TRUE(s.constraints.rigid_groups.empty());
      EXPECT_EQ(s.applied_forces.size(), 0);
      for (int n = 0; n < l.node_count(); ++n) {
        if (on_surface(l.shape, n)) {
          Eigen::Vector3d p = ref.col(n);
          p[direction] += std::tan(gamma) * ref(normal, n);
          expect_held_at(s.constraints, n, p);
        } else {
          EXPECT_EQ(held_coordinates(s.constraints, n), 0) << "interior node " << n;
        }
      }
    }
  }
  // The upper face of the normal moves by tan(gamma) L on the initial lattice.
  const mp::LoadState s =
      mp::strain_load(l, strain_spec(cfg::LoadKind::shear, 0, 1), 0.2, l.positions);
  const int corner = l.shape.node_index(4, 5, 6);
  EXPECT_NEAR(s.constraints.prescribed(1, corner) - l.positions(1, corner),
              std::tan(0.2) * 4.0 * l.element_length, 1e-20);
}

// strain_shearing, value != 0: both faces normal to `normal` on the affine field, the rest free.
TEST(Loading, ShearOnTheNormalFacesHoldsOnlyThoseFaces) {
  const lat::Lattice l = block();
  const Eigen::Matrix3Xd ref = shifted_reference(l);
  const int normal = 1;
  const int direction = 0;
  const double gamma = 0.15;
  const mp::LoadState s = mp::strain_load(
      l, strain_spec(cfg::LoadKind::shear, normal, direction, cfg::ShearBoundary::normal_faces),
      gamma, ref);
  EXPECT_TRUE(s.constraints.rigid_groups.empty());
  for (int n = 0; n < l.node_count(); ++n) {
    if (on_face(l.shape, n, normal, false) || on_face(l.shape, n, normal, true)) {
      Eigen::Vector3d p = ref.col(n);
      p[direction] += std::tan(gamma) * ref(normal, n);
      expect_held_at(s.constraints, n, p);
    } else {
      EXPECT_EQ(held_coordinates(s.constraints, n), 0) << "node " << n;
    }
  }
}

// Tension 0.05 along y and compression -0.05 along x: lower face at the reference, upper face's
// normal coordinate ref * (1 + value), its other coordinates at the reference; the rest free.
TEST(Loading, TensionScalesTheUpperFaceAlongTheNormal) {
  const lat::Lattice l = block();
  const Eigen::Matrix3Xd ref = shifted_reference(l);
  for (const auto& [kind, normal, value] : {std::tuple{cfg::LoadKind::tension, 1, 0.05},
                                            std::tuple{cfg::LoadKind::compression, 0, -0.05},
                                            std::tuple{cfg::LoadKind::tension, 2, 0.5}}) {
    SCOPED_TRACE(cfg::to_string(kind) + " normal " + std::to_string(normal));
    const mp::LoadState s = mp::strain_load(l, strain_spec(kind, normal, normal), value, ref);
    EXPECT_TRUE(s.constraints.rigid_groups.empty());
    EXPECT_EQ(s.applied_forces.size(), 0);
    for (int n = 0; n < l.node_count(); ++n) {
      if (on_face(l.shape, n, normal, false)) {
        expect_held_at(s.constraints, n, ref.col(n), 0.0);
      } else if (on_face(l.shape, n, normal, true)) {
        Eigen::Vector3d p = ref.col(n);
        p[normal] = ref(normal, n) * (1.0 + value);
        expect_held_at(s.constraints, n, p);
      } else {
        EXPECT_EQ(held_coordinates(s.constraints, n), 0) << "node " << n;
      }
    }
  }
}

// Torsion: the upper face turned by the angle, right-handed about +normal, about the box's axis
// (the line through the centre of the cross-section); the lower face unchanged. Checked against
// hand-written rotations for normal z and normal x (y -> z under a positive angle).
TEST(Loading, TorsionTurnsTheUpperFaceAboutTheBoxAxis) {
  const lat::Lattice l = block();
  const double le = l.element_length;
  const double angle = 0.3;
  const double c = std::cos(angle);
  const double s = std::sin(angle);
  {  // normal z: box 4 x 5 x 6 l_e, axis through (2, 2.5) l_e
    const mp::LoadState st =
        mp::strain_load(l, strain_spec(cfg::LoadKind::torsion, 2, 2), angle, l.positions);
    for (int n = 0; n < l.node_count(); ++n) {
      const auto g = l.shape.node_coordinates(n);
      if (g[2] == 0) {
        expect_held_at(st.constraints, n, l.positions.col(n), 0.0);
      } else if (g[2] == 6) {
        const double u = g[0] - 2.0;
        const double v = g[1] - 2.5;
        expect_held_at(st.constraints, n,
                       le * Eigen::Vector3d(2.0 + c * u - s * v, 2.5 + s * u + c * v, 6.0), 1e-18);
      } else {
        EXPECT_EQ(held_coordinates(st.constraints, n), 0) << "node " << n;
      }
    }
  }
  {  // normal x on a perturbed reference: axis through (y, z) = (2.5, 3) l_e
    const Eigen::Matrix3Xd ref = shifted_reference(l);
    const mp::LoadState st =
        mp::strain_load(l, strain_spec(cfg::LoadKind::torsion, 0, 0), -angle, ref);
    for (int n = 0; n < l.node_count(); ++n) {
      if (on_face(l.shape, n, 0, false)) {
        expect_held_at(st.constraints, n, ref.col(n), 0.0);
      } else if (on_face(l.shape, n, 0, true)) {
        const double u = ref(1, n) - 2.5 * le;
        const double v = ref(2, n) - 3.0 * le;
        // -angle about +x: (u, v) -> (c u + s v, -s u + c v)
        expect_held_at(
            st.constraints, n,
            Eigen::Vector3d(ref(0, n), 2.5 * le + c * u + s * v, 3.0 * le - s * u + c * v), 1e-18);
      } else {
        EXPECT_EQ(held_coordinates(st.constraints, n), 0) << "node " << n;
      }
    }
  }
}

// one_face: the lower face held at the reference; every node of the upper face gets
// stress A / n along the right axis, so the forces add up to stress x area.
TEST(Loading, OneFaceStressLoadsTheUpperFace) {
  const lat::Lattice l = block();
  const Eigen::Vector3d L = l.box_lengths();  // 4, 5, 6 um
  const Eigen::Matrix3Xd ref = shifted_reference(l);
  for (const auto& [kind, normal, direction, value] :
       {std::tuple{cfg::LoadKind::shear, 0, 2, 250.0},
        std::tuple{cfg::LoadKind::tension, 1, 1, 80.0},
        std::tuple{cfg::LoadKind::compression, 2, 2, -40.0},
        std::tuple{cfg::LoadKind::shear, 2, 1, -100.0}}) {
    SCOPED_TRACE(cfg::to_string(kind) + " normal " + std::to_string(normal));
    const mp::LoadState s = mp::stress_load(
        l, stress_spec(kind, normal, direction, cfg::StressLoading::one_face), value, ref);
    ASSERT_EQ(s.applied_forces.cols(), l.node_count());
    EXPECT_TRUE(s.constraints.rigid_groups.empty());
    const double area = L.prod() / L[normal];
    const Eigen::Vector3d total = s.applied_forces.rowwise().sum();
    const double scale = std::abs(value) * area;
    EXPECT_NEAR(total[direction], value * area, 1e-14 * scale);
    EXPECT_NEAR(total.norm(), std::abs(value) * area, 1e-14 * scale);
    const int face_size = static_cast<int>(l.node_count()) / l.shape.nodes[normal];
    for (int n = 0; n < l.node_count(); ++n) {
      if (on_face(l.shape, n, normal, true)) {
        EXPECT_NEAR(s.applied_forces(direction, n), value * area / face_size, 1e-14 * scale);
      } else {
        EXPECT_EQ(s.applied_forces.col(n).norm(), 0.0) << "node " << n;
      }
      if (on_face(l.shape, n, normal, false)) {
        expect_held_at(s.constraints, n, ref.col(n), 0.0);
      } else {
        EXPECT_EQ(held_coordinates(s.constraints, n), 0) << "node " << n;
      }
    }
  }
}

// both_faces: nothing held; the forces have no net force and no net torque about the box centre;
// each loaded face carries stress x its area.
TEST(Loading, BothFacesStressHasNoNetForceOrTorque) {
  const lat::Lattice l = block();
  const Eigen::Vector3d L = l.box_lengths();
  const Eigen::Vector3d centre = 0.5 * L;
  for (const auto& [kind, normal, direction, value] :
       {std::tuple{cfg::LoadKind::shear, 1, 2, 300.0},
        std::tuple{cfg::LoadKind::shear, 0, 1, -70.0},
        std::tuple{cfg::LoadKind::tension, 0, 0, 120.0}}) {
    SCOPED_TRACE(cfg::to_string(kind) + " normal " + std::to_string(normal));
    const mp::LoadState s =
        mp::stress_load(l, stress_spec(kind, normal, direction, cfg::StressLoading::both_faces),
                        value, l.positions);
    const mess::BoundaryConstraints& c = s.constraints;
    EXPECT_TRUE(c.rigid_groups.empty());
    for (int n = 0; n < l.node_count(); ++n) EXPECT_EQ(held_coordinates(c, n), 0);
    const double scale = std::abs(value) * L.prod() / L.minCoeff();
    Eigen::Vector3d force = Eigen::Vector3d::Zero();
    Eigen::Vector3d torque = Eigen::Vector3d::Zero();
    double upper_along = 0.0;   // upper face of normal, along direction
    double upper_normal = 0.0;  // upper face of direction, along normal (shear)
    for (int n = 0; n < l.node_count(); ++n) {
      const Eigen::Vector3d f = s.applied_forces.col(n);
      force += f;
      torque += (l.positions.col(n) - centre).cross(f);
      if (on_face(l.shape, n, normal, true)) upper_along += f[direction];
      if (kind == cfg::LoadKind::shear && on_face(l.shape, n, direction, true)) {
        upper_normal += f[normal];
      }
    }
    EXPECT_LT(force.norm(), 1e-14 * scale);
    EXPECT_LT(torque.norm(), 1e-14 * scale * L.maxCoeff());
    EXPECT_NEAR(upper_along, value * L.prod() / L[normal], 1e-14 * scale);
    if (kind == cfg::LoadKind::shear) {
      EXPECT_NEAR(upper_normal, value * L.prod() / L[direction], 1e-14 * scale);
      // Without the complementary pair the couple would be value * V.
      EXPECT_GT(std::abs(value) * L.prod(), 1e6 * torque.norm());
    }
  }
}

TEST(Loading, ImpossibleInputsThrowNamingTheValue) {
  const lat::Lattice l = block();
  const Eigen::Matrix3Xd& x = l.positions;
  const auto strain_message = [&](const cfg::StrainSpec& spec, double value,
                                  const Eigen::Matrix3Xd& ref) -> std::string {
    try {
      mp::strain_load(l, spec, value, ref);
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
    return "(no exception)";
  };
  const auto tension = strain_spec(cfg::LoadKind::tension, 2, 2);
  const auto compression = strain_spec(cfg::LoadKind::compression, 0, 0);
  EXPECT_NE(strain_message(tension, 1.0, x).find("value = 1"), std::string::npos);
  EXPECT_NE(strain_message(compression, -1.0, x).find("value = -1"), std::string::npos);
  EXPECT_NE(strain_message(compression, -1.5, x).find("-1.5"), std::string::npos);
  EXPECT_NE(strain_message(compression, 0.1, x).find("0.1"), std::string::npos);
  EXPECT_NE(strain_message(tension, -0.1, x).find("-0.1"), std::string::npos);
  EXPECT_NE(strain_message(tension, std::numeric_limits<double>::quiet_NaN(), x).find("nan"),
            std::string::npos);
  EXPECT_NE(strain_message(strain_spec(cfg::LoadKind::shear, 1, 1), 0.1, x).find("direction = 1"),
            std::string::npos);
  EXPECT_NE(strain_message(strain_spec(cfg::LoadKind::shear, 2, 0), 1.6, x).find("1.6"),
            std::string::npos);
  EXPECT_NE(strain_message(strain_spec(cfg::LoadKind::tension, 3, 3), 0.1, x).find("normal = 3"),
            std::string::npos);
  EXPECT_NE(strain_message(tension, 0.1, Eigen::Matrix3Xd::Zero(3, 5)).find("5 columns"),
            std::string::npos);
  EXPECT_NO_THROW(mp::strain_load(l, tension, 0.999, x));
  EXPECT_NO_THROW(mp::strain_load(l, strain_spec(cfg::LoadKind::torsion, 2, 2), -3.0, x));

  const auto stress = [&](cfg::LoadKind kind, int normal, int direction, double value) {
    mp::stress_load(l, stress_spec(kind, normal, direction, cfg::StressLoading::one_face), value,
                    x);
  };
  EXPECT_THROW(stress(cfg::LoadKind::compression, 2, 2, 10.0), std::invalid_argument);
  EXPECT_THROW(stress(cfg::LoadKind::tension, 2, 2, -10.0), std::invalid_argument);
  EXPECT_THROW(stress(cfg::LoadKind::shear, 0, 0, 10.0), std::invalid_argument);
  EXPECT_THROW(stress(cfg::LoadKind::shear, 0, -1, 10.0), std::invalid_argument);
  EXPECT_THROW(stress(cfg::LoadKind::torsion, 2, 2, 10.0), std::invalid_argument);
  EXPECT_THROW(stress(cfg::LoadKind::shear, 2, 0, std::numeric_limits<double>::infinity()),
               std::invalid_argument);
  EXPECT_THROW(mp::hysteresis_load(l, Eigen::Matrix3Xd::Zero(3, 3)), std::invalid_argument);
  EXPECT_THROW(mp::magnetostriction_load(l, Eigen::Matrix3Xd::Zero(3, 3)), std::invalid_argument);
  EXPECT_THROW(
      mp::measured_strain(l, stress_spec(cfg::LoadKind::shear, 2, 0, cfg::StressLoading::one_face),
                          Eigen::Matrix3Xd::Zero(3, 3), x),
      std::invalid_argument);
}

// ----------------------------------------------------------------------------- measured_strain

// Affine configurations give back the strain they were made with: simple shear
// x_d += tan(gamma) x_n and uniaxial stretch for one_face; for both_faces the lower face moves
// too (a rigid translation is added), and shear is pure shear (each face pair slides by
// tan(gamma/2)), whose engineering shear angle is gamma.
TEST(Loading, MeasuredStrainOfAffineConfigurations) {
  const lat::Lattice l = block();
  const Eigen::Matrix3Xd& x0 = l.positions;
  const Eigen::Vector3d shift(0.3e-6, -0.2e-6, 0.1e-6);
  for (const auto& [normal, direction] : {std::pair{2, 0}, std::pair{0, 1}, std::pair{1, 2}}) {
    SCOPED_TRACE("normal " + std::to_string(normal) + " direction " + std::to_string(direction));
    const double gamma = 0.07;
    Eigen::Matrix3Xd simple = x0;
    simple.row(direction) += std::tan(gamma) * x0.row(normal);
    EXPECT_NEAR(
        mp::measured_strain(
            l, stress_spec(cfg::LoadKind::shear, normal, direction, cfg::StressLoading::one_face),
            simple, x0),
        gamma, 1e-14);

    Eigen::Matrix3Xd pure = x0;
    const double t = std::tan(gamma / 2.0);
    pure.row(direction) += t * x0.row(normal);
    pure.row(normal) += t * x0.row(direction);
    pure.colwise() += shift;
    EXPECT_NEAR(
        mp::measured_strain(
            l, stress_spec(cfg::LoadKind::shear, normal, direction, cfg::StressLoading::both_faces),
            pure, x0),
        gamma, 1e-14);

    for (const double eps : {0.03, -0.02}) {
      const cfg::LoadKind kind = eps > 0 ? cfg::LoadKind::tension : cfg::LoadKind::compression;
      Eigen::Matrix3Xd stretched = x0;
      stretched.row(normal) *= 1.0 + eps;
      for (const int other : {(normal + 1) % 3, (normal + 2) % 3}) {
        stretched.row(other) *= 1.0 - 0.4 * eps;  // lateral contraction must not matter
      }
      EXPECT_NEAR(
          mp::measured_strain(l, stress_spec(kind, normal, normal, cfg::StressLoading::one_face),
                              stretched, x0),
          eps, 1e-14);
      stretched.colwise() += shift;
      EXPECT_NEAR(
          mp::measured_strain(l, stress_spec(kind, normal, normal, cfg::StressLoading::both_faces),
                              stretched, x0),
          eps, 1e-14);
    }
  }
  // Relative to a reference that is not the initial lattice: the displacement over the
  // reference's own face distance.
  const Eigen::Matrix3Xd ref = shifted_reference(l);
  Eigen::Matrix3Xd x = ref;
  x.row(1) += 0.04 * x0.row(0);  // face x = 0 stays, face x = L slides 0.04 L = 0.16 l_e
  double upper = 0.0;
  double lower = 0.0;
  for (int n = 0; n < l.node_count(); ++n) {
    if (on_face(l.shape, n, 0, true)) upper += ref(0, n) / 42.0;  // 6 x 7 nodes per face
    if (on_face(l.shape, n, 0, false)) lower += ref(0, n) / 42.0;
  }
  EXPECT_NEAR(mp::measured_strain(
                  l, stress_spec(cfg::LoadKind::shear, 0, 1, cfg::StressLoading::one_face), x, ref),
              std::atan(0.16 * l.element_length / (upper - lower)), 1e-14);
}

// ------------------------------------------------------------------------------------- physics

namespace {

struct TensionResult {
  double energy = 0.0;    // J, relaxed
  double reaction = 0.0;  // N, net force the held upper face exerts along the normal
  Eigen::Vector3d stretch = Eigen::Vector3d::Zero();  // mean face distance / L - 1 per axis
};

// Relaxes `sys` (constraints set), then measures it.
TensionResult relaxed_tension(mess::MessSystem& sys, int normal) {
  const mess::MinimiserResult r = relax(sys);
  EXPECT_TRUE(r.converged) << mess::to_string(r.status);
  const lat::Lattice& l = sys.lattice();
  TensionResult out;
  out.energy = r.final.energies.total();
  Eigen::Matrix3Xd g;
  sys.evaluate(&g);
  for (int n = 0; n < l.node_count(); ++n) {
    if (on_face(l.shape, n, normal, true)) out.reaction += g(normal, n);
  }
  for (int a = 0; a < 3; ++a) {
    double upper = 0.0;
    double lower = 0.0;
    int count = 0;
    for (int n = 0; n < l.node_count(); ++n) {
      if (on_face(l.shape, n, a, true)) {
        upper += sys.positions()(a, n);
        ++count;
      }
      if (on_face(l.shape, n, a, false)) lower += sys.positions()(a, n);
    }
    out.stretch[a] = (upper - lower) / count / l.box_lengths()[a] - 1.0;
  }
  return out;
}

// Uniaxial tension with free lateral faces: only the normal coordinate of both loaded faces is
// held (lower at 0, upper at L (1 + eps)), plus the fewest holds that remove the rigid motions
// left (translations across the normal, rotation about it): the origin corner's two lateral
// coordinates and, for a second corner of the lower face, the coordinate the rotation would
// move. The homogeneous uniaxial-stress state meets all of these, so it is the solution.
TensionResult free_tension(const lat::Lattice& l, int normal, double eps) {
  mess::MessSystem sys =
      mess::MessSystem::make(l, Eigen::Vector3d::Zero(), mess::model_profile("physical"));
  mess::BoundaryConstraints c = mess::BoundaryConstraints::none(l.node_count());
  const auto hold = [&](int node, int axis, double value) { c.hold(node, axis, value); };
  for (int n = 0; n < l.node_count(); ++n) {
    if (on_face(l.shape, n, normal, false)) hold(n, normal, 0.0);
    if (on_face(l.shape, n, normal, true)) hold(n, normal, l.positions(normal, n) * (1.0 + eps));
  }
  const int a = (normal + 1) % 3;
  const int b = (normal + 2) % 3;
  hold(l.shape.node_index(0, 0, 0), a, 0.0);
  hold(l.shape.node_index(0, 0, 0), b, 0.0);
  std::array<int, 3> corner{0, 0, 0};
  corner[b] = l.shape.nodes[b] - 1;  // on the lower face, at a = 0: rotation moves it along a
  hold(l.shape.node_index(corner[0], corner[1], corner[2]), a, 0.0);
  sys.set_constraints(c);
  return relaxed_tension(sys, normal);
}

// The protocol's tension (strain_load): both loaded faces clamped, lateral faces free.
TensionResult clamped_tension(const lat::Lattice& l, int normal, double eps) {
  mess::MessSystem sys =
      mess::MessSystem::make(l, Eigen::Vector3d::Zero(), mess::model_profile("physical"));
  const cfg::LoadKind kind = eps > 0 ? cfg::LoadKind::tension : cfg::LoadKind::compression;
  sys.set_constraints(
      mp::strain_load(l, strain_spec(kind, normal, normal), eps, l.positions).constraints);
  return relaxed_tension(sys, normal);
}

}  // namespace

// (a) The physical lattice reproduces E and nu exactly for homogeneous strain (docs/lattice.md),
// so free uniaxial tension of a particle-free block must give them back: E from the energy,
// U = E eps^2 V / 2, and from the reaction force, sigma = F / A = E eps; nu = -lateral / axial
// strain. The springs are geometrically nonlinear, so U, F and the lateral strain have O(eps)
// relative corrections; the mean of +eps and -eps cancels them (what is left is O(eps^2)).
TEST(LoadingPhysics, FreeUniaxialTensionRecoversEAndNu) {
  const double E = 9.0e3;
  const double eps = 1e-4;
  for (const auto& [nu, normal] : {std::pair{0.47, 0}, std::pair{0.3, 1}}) {
    SCOPED_TRACE("nu " + std::to_string(nu) + " normal " + std::to_string(normal));
    const lat::Lattice l = block(nu);
    const Eigen::Vector3d L = l.box_lengths();
    const double V = L.prod();
    const TensionResult plus = free_tension(l, normal, eps);
    const TensionResult minus = free_tension(l, normal, -eps);
    const double e_energy = (plus.energy + minus.energy) / (eps * eps * V);
    const double e_force = (plus.reaction - minus.reaction) / (2.0 * eps) / (V / L[normal]);
    EXPECT_NEAR(plus.stretch[normal], eps, 1e-15);
    for (const int lateral : {(normal + 1) % 3, (normal + 2) % 3}) {
      const double nu_measured = -(plus.stretch[lateral] - minus.stretch[lateral]) / (2.0 * eps);
      EXPECT_NEAR(nu_measured, nu, 1e-6 * nu) << "lateral axis " << lateral;
    }
    EXPECT_NEAR(e_energy, E, 1e-6 * E);
    EXPECT_NEAR(e_force, E, 1e-6 * E);
  }
}

// (b) The protocol's tension clamps both loaded faces (no lateral contraction there), which
// stiffens a short block: its apparent modulus 2 U / (eps^2 V) (mean of +eps and -eps) is a
// property of the block's shape and resolution, not of the lattice. Measured (physical profile,
// E = 9 kPa, 5 x 6 x 7 nodes): nu = 0.47, normal z (6 l_e long, 4 x 5 l_e across): 1.1952 E;
// nu = 0.3, normal z: 1.0643 E; nu = 0.47, normal x (4 l_e long, 5 x 6 across): 1.4094 E. The
// same shape at 2x and 3x the resolution (9 x 11 x 13, 13 x 16 x 19 nodes; nu = 0.47, z) gives
// 1.1609 E and 1.1514 E: about 15 % is the clamping itself (it stays as the lattice is refined)
// and the rest (3-4 % here, shrinking with resolution) discretisation near the clamped edges.
// Asserted: above E, and within 0.005 E of the measured values.
TEST(LoadingPhysics, ClampedTensionIsStifferThanE) {
  const double E = 9.0e3;
  const double eps = 1e-4;
  for (const auto& [nu, normal, measured] :
       {std::tuple{0.47, 2, 1.1952}, std::tuple{0.3, 2, 1.0643}, std::tuple{0.47, 0, 1.4094}}) {
    SCOPED_TRACE("nu " + std::to_string(nu) + " normal " + std::to_string(normal));
    const lat::Lattice l = block(nu);
    const double V = l.box_lengths().prod();
    const TensionResult plus = clamped_tension(l, normal, eps);
    const TensionResult minus = clamped_tension(l, normal, -eps);
    const double e_apparent = (plus.energy + minus.energy) / (eps * eps * V);
    EXPECT_GT(e_apparent, E);
    EXPECT_NEAR(e_apparent / E, measured, 0.005);
    // The clamped faces stay where the protocol put them.
    EXPECT_NEAR(plus.stretch[normal], eps, 1e-15);
  }
}

// (c) Simple shear of the whole boundary (strain_load, all_faces; eq. 4.96) is homogeneous, so
// the energy density is G gamma^2 / 2, G = E / (2 (1 + nu)); the O(gamma^2) relative
// corrections (tan, nonlinear springs) are 1e-8 at gamma = 1e-4.
TEST(LoadingPhysics, SimpleShearEnergyDensityIsGGammaSquaredOverTwo) {
  const double E = 9.0e3;
  const double gamma = 1e-4;
  for (const auto& [nu, normal, direction] : {std::tuple{0.47, 0, 1}, std::tuple{0.3, 2, 0}}) {
    SCOPED_TRACE("nu " + std::to_string(nu) + " normal " + std::to_string(normal));
    const lat::Lattice l = block(nu);
    mess::MessSystem sys =
        mess::MessSystem::make(l, Eigen::Vector3d::Zero(), mess::model_profile("physical"));
    sys.set_constraints(
        mp::strain_load(l, strain_spec(cfg::LoadKind::shear, normal, direction), gamma, l.positions)
            .constraints);
    const mess::MinimiserResult r = relax(sys);
    ASSERT_TRUE(r.converged) << mess::to_string(r.status);
    const double G = E / (2.0 * (1.0 + nu));
    const double density = r.final.energies.total() / l.box_lengths().prod();
    EXPECT_NEAR(density, 0.5 * G * gamma * gamma, 1e-6 * density);
  }
}

// Stress runs (stress_load, measured_strain) on the particle-free block, nu = 0.47: modulus =
// stress / measured strain. The original's equal nodal forces (edges and corners get a full
// share, docs/original-code.md#boundary-conditions) are not a uniform traction: they overload the
// face's perimeter, so a free block (both_faces) looks softer than it is. Measured on 5 x 6 x 7
// nodes: both_faces tension 0.8866 E, shear 0.8822 G (with the 1/N perimeter error: tension 0.9475
// E at 9 x 11 x 13 nodes, 0.9700 E at 13 x 16 x 19); one_face tension 1.0174 E (clamped lower face
// stiffens, the perimeter softens); one_face shear 0.2890 G (a short block under a shear force on
// its top face and held at its bottom mostly bends). Asserted within 0.005 of those values.
TEST(LoadingPhysics, StressRunsMeasureTheModuli) {
  const double E = 9.0e3;
  const double nu = 0.47;
  const double G = E / (2.0 * (1.0 + nu));
  const lat::Lattice l = block(nu);
  for (const auto& [kind, direction, loading, value, measured] :
       {std::tuple{cfg::LoadKind::tension, 2, cfg::StressLoading::both_faces, 0.9, 0.8866},
        std::tuple{cfg::LoadKind::tension, 2, cfg::StressLoading::one_face, 0.9, 1.0174},
        std::tuple{cfg::LoadKind::shear, 0, cfg::StressLoading::both_faces, 0.3, 0.8822},
        std::tuple{cfg::LoadKind::shear, 0, cfg::StressLoading::one_face, 0.3, 0.2890}}) {
    const cfg::StressSpec spec = stress_spec(kind, 2, direction, loading);
    SCOPED_TRACE(cfg::to_string(kind) +
                 (loading == cfg::StressLoading::one_face ? " one_face" : " both_faces"));
    mess::MessSystem sys =
        mess::MessSystem::make(l, Eigen::Vector3d::Zero(), mess::model_profile("physical"));
    const mp::LoadState s = mp::stress_load(l, spec, value, l.positions);
    sys.set_constraints(s.constraints);
    sys.set_applied_forces(s.applied_forces);
    const mess::MinimiserResult r = relax(sys);
    ASSERT_TRUE(r.converged) << mess::to_string(r.status);
    const double strain = mp::measured_strain(l, spec, sys.positions(), l.positions);
    const double modulus = value / strain;
    EXPECT_NEAR(modulus / (kind == cfg::LoadKind::shear ? G : E), measured, 0.005);
  }
}
