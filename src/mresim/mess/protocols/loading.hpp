#pragma once

// Boundary conditions of the 3D protocols (Section 4.2.7;
// docs/original-code.md#boundary-conditions): which node coordinates are held where, which faces
// float as rigid bodies, and which nodal forces a stress applies. One function per protocol family;
// the protocol runner (protocol_runner.hpp) calls them once per step and hands the result to
// MessSystem.
//
// Faces: the "lower" face of axis a is the face at coordinate 0 (left, front, bottom for x, y,
// z), the "upper" face the one at (N_a - 1) l_e. `reference` is the configuration the load is
// measured from (3 x N, m): the initial lattice for hysteresis and magnetostriction, and for
// strain runs the converged zero-strain state at the same field
// (docs/original-code.md#boundary-conditions).

#include <Eigen/Core>

#include "mresim/mess/lattice/lattice.hpp"
#include "mresim/mess/run_file/mess_spec.hpp"
#include "mresim/mess/system/constraints.hpp"

namespace mresim::mess_protocol {

// What a step prescribes: constraints (held coordinates already filled in `prescribed`) and
// applied nodal forces (N, 3 x N; empty = none).
struct LoadState {
  mess::BoundaryConstraints constraints;
  Eigen::Matrix3Xd applied_forces;
};

// Hysteresis: all six faces held at `reference` (the initial lattice).
LoadState hysteresis_load(const lattice::Lattice& lattice, const Eigen::Matrix3Xd& reference);

// Magnetostriction: the bottom face (z = 0) held at `reference`; everything else free.
LoadState magnetostriction_load(const lattice::Lattice& lattice, const Eigen::Matrix3Xd& reference);

// Strain runs (mess_strain), value as stored in StrainSpec::values:
//  - value == 0, tension/compression/torsion, and shear with normal_faces: the lower face of
//    `normal` held at `reference`, the upper face one rigid group (floats as a rigid body);
//  - shear with all_faces (any value, including 0): every surface node held at
//    reference + tan(gamma) h e_direction, h = its reference coordinate along `normal` (the
//    affine simple-shear field on the whole boundary, eq. 4.96);
//  - shear with normal_faces, value != 0: both faces normal to `normal` held at that affine
//    field; side faces free;
//  - tension/compression, value != 0: both faces normal to `normal` held at `reference`, the
//    upper face's coordinate along `normal` replaced by reference * (1 + value);
//  - torsion, value != 0: both faces normal to `normal` held, the upper face rotated by
//    `value` (rad, right-handed about +normal) about the box's axis along `normal` (the line
//    through the centre of the box's cross-section).
LoadState strain_load(const lattice::Lattice& lattice, const mess_config::StrainSpec& strain,
                      double value, const Eigen::Matrix3Xd& reference);

// Stress runs (mess_stress), value in Pa as stored in StressSpec::values:
//  - one_face: the lower face of `normal` held at `reference` (the initial lattice); every node
//    of the upper face gets force value * A / n along `direction` (shear) or `normal`
//    (tension/compression; compression values are negative), A the initial area of that face
//    and n its node count (edges and corners get the same force, as the original);
//  - both_faces: nothing held; +f on the upper face and -f on the lower face; for shear also
//    +f / -f along `normal` on the upper / lower faces normal to `direction` (so the applied
//    forces have no net force and no net torque).
LoadState stress_load(const lattice::Lattice& lattice, const mess_config::StressSpec& stress,
                      double value, const Eigen::Matrix3Xd& reference);

// The strain a stress run reached, measured on the upper face of `normal` relative to
// `reference`: shear: atan(mean displacement along direction / face height); tension,
// compression: mean displacement along normal / face height (engineering strain).
double measured_strain(const lattice::Lattice& lattice, const mess_config::StressSpec& stress,
                       const Eigen::Matrix3Xd& positions, const Eigen::Matrix3Xd& reference);

}  // namespace mresim::mess_protocol
