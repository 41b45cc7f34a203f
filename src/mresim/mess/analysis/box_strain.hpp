#pragma once

// The strain of the whole box (magnetostriction; docs/outputs-3d.md): along each axis a,
//
//   e_a = (mean_a(upper face) - mean_a(lower face)) / (the same in the initial lattice) - 1,
//
// mean_a(face) the mean a-coordinate of the nodes of the outer face normal to a (edges and
// corners included; lattice::face_nodes): x right/left, y back/front, z top/bottom. For an affine
// deformation x -> F X it is F_aa - 1 exactly (the faces' mean coordinates map with F and the
// faces are symmetric about the box's mid-planes, so the off-diagonal terms cancel); for a
// free face it is the face's mean displacement, which is how an experiment measures the sample's
// length change. The magnetostriction along the field direction d (a unit vector) is
// sum_a d_a^2 e_a: exact for the diagonal of the strain (the off-diagonal terms are not measured
// by face means).

#include <Eigen/Core>

#include "mresim/mess/lattice/lattice.hpp"

namespace mresim::mess_analysis {

// positions: 3 x N, the lattice's node order (m). NaN components where a face mean is not finite.
Eigen::Vector3d box_strain(const lattice::Lattice& lattice, const Eigen::Matrix3Xd& positions);

// sum_a d_a^2 e_a for a unit field direction d.
double strain_along(const Eigen::Vector3d& box_strain, const Eigen::Vector3d& direction);

}  // namespace mresim::mess_analysis
