#pragma once

// The orientation of the closest pair of particles (docs/outputs-3d.md, /steps/pair_angle):
// the angle between the centre-to-centre vector of the two particles closest to each other and
// a reference axis (the field direction),
//
//   theta = arccos(|r . d| / |r|),   r = c_j - c_i, |d| = 1,   theta in [0, pi/2].
//
// The pair has no order, so r and -r give the same angle: 0 when the pair lies along the axis
// (the chains of Figs. 4.11-4.13), pi/2 side by side (Fig. 4.23's field across the chain). Under
// shear the angle is how far the strain tilts the pair out of the field (Section 4.3.2: the
// rearrangement "tends to reduce the tip-to-tail alignment", Fig. 4.22). The original's
// get_particle_orientation (analysis_workflows.py) measured something else: each particle's own
// rotation, from two of its nodes, as polar and azimuthal angles against fixed z and x axes.

#include <Eigen/Core>

namespace mresim::mess_analysis {

struct ClosestPair {
  Eigen::Index first = -1;   // lower index; -1 with fewer than two particles
  Eigen::Index second = -1;  // higher index
  double distance = 0.0;     // m
};

// The pair with the smallest centre-to-centre distance (the first such pair in index order on
// ties). centres: 3 x N_p, finite.
ClosestPair closest_pair(const Eigen::Matrix3Xd& centres);

// theta above for the closest pair and the unit axis d; NaN with fewer than two particles or
// non-finite centres.
double pair_angle(const Eigen::Matrix3Xd& centres, const Eigen::Vector3d& axis);

}  // namespace mresim::mess_analysis
