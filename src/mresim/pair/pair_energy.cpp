#include "mresim/pair/pair_energy.hpp"

#include "mresim/pair/overlap_penalty.hpp"

namespace mresim::pair {

PairEnergy::PairEnergy(const PairSystem& system, const Eigen::Vector3d& applied_field_tesla)
    : system_(system),
      reduced_field_(applied_field_tesla / (kMu0 * system.material.saturation_magnetization)),
      radius_(system.material.radius),
      energy_scale_(system.material.magnetic_energy_scale()),
      k12_(system.springs.k12 * radius_ * radius_ / energy_scale_),
      k0_(system.springs.model == SpringModel::three
              ? system.springs.k0 * radius_ * radius_ / energy_scale_
              : 0.0),
      rest_(system.springs.rest_separation / radius_) {}

PairMagnetization PairEnergy::magnetization(const Eigen::Vector3d& d) const {
  return solve_pair_magnetization(d, reduced_field_, system_.material.susceptibility);
}

EnergyBreakdown PairEnergy::scaled_terms(const Eigen::Vector3d& d,
                                         const PairMagnetization& mag) const {
  const Eigen::Vector3d& m = mag.m;
  EnergyBreakdown e;
  // Eq. 2.3 with m1 = m2 = m: Zeeman and self-energy for both spheres; the dipole term
  // -(1/2) sum_i m_i . h_dip,i = -m . D m.
  e.zeeman = -2.0 * m.dot(reduced_field_);
  e.dipole = -m.dot(dipole_coupling(d) * m);
  e.self = m.squaredNorm() / system_.material.susceptibility;
  const double s = d.norm();
  e.spring = 0.5 * k12_ * (s - rest_) * (s - rest_);
  const Eigen::Vector3d d0(rest_, 0.0, 0.0);
  e.anchor = 0.25 * k0_ * (d - d0).squaredNorm();  // eq. 2.4 after removing the centre of mass
  e.penalty = overlap_penalty(system_.penalty, radius_, s * radius_).energy / energy_scale_;
  return e;
}

double PairEnergy::scaled_energy(const Eigen::Vector3d& d) const {
  return scaled_terms(d, magnetization(d)).total();
}

Eigen::Vector3d PairEnergy::scaled_gradient(const Eigen::Vector3d& d) const {
  return scaled_gradient_at(d, magnetization(d).m);
}

double PairEnergy::scaled_energy_and_gradient(const Eigen::Vector3d& d,
                                              Eigen::Vector3d& gradient) const {
  const PairMagnetization mag = magnetization(d);
  gradient = scaled_gradient_at(d, mag.m);
  return scaled_terms(d, mag).total();
}

Eigen::Vector3d PairEnergy::scaled_gradient_at(const Eigen::Vector3d& d,
                                               const Eigen::Vector3d& m) const {
  const double s2 = d.squaredNorm();
  const double s = std::sqrt(s2);
  const double s5 = s2 * s2 * s;
  const double dm = d.dot(m);
  // d/dd of -m.D m = -((d.m)^2 / S^5 - m^2 / (3 S^3)).
  Eigen::Vector3d g =
      -2.0 * dm / s5 * m + (5.0 * dm * dm / (s5 * s2) - m.squaredNorm() / s5) * d;
  const Eigen::Vector3d n = d / s;
  const double penalty_slope =
      overlap_penalty(system_.penalty, radius_, s * radius_).derivative * radius_ / energy_scale_;
  g += (k12_ * (s - rest_) + penalty_slope) * n;
  const Eigen::Vector3d d0(rest_, 0.0, 0.0);
  g += 0.5 * k0_ * (d - d0);
  return g;
}

EnergyBreakdown PairEnergy::breakdown(const Eigen::Vector3d& d) const {
  EnergyBreakdown e = scaled_terms(d, magnetization(d));
  for (double* term : {&e.zeeman, &e.dipole, &e.self, &e.spring, &e.anchor, &e.penalty}) {
    *term *= energy_scale_;
  }
  return e;
}

}  // namespace mresim::pair
