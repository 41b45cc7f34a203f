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

Eigen::Vector3d PairEnergy::magnetic_gradient(const Eigen::Vector3d& d,
                                              const Eigen::Vector3d& m) const {
  const double s2 = d.squaredNorm();
  const double s5 = s2 * s2 * std::sqrt(s2);
  const double dm = d.dot(m);
  // d/dd of -m.D m = -((d.m)^2 / S^5 - m^2 / (3 S^3)) at fixed m.
  return -2.0 * dm / s5 * m + (5.0 * dm * dm / (s5 * s2) - m.squaredNorm() / s5) * d;
}

Eigen::Vector3d PairEnergy::scaled_gradient_at(const Eigen::Vector3d& d,
                                               const Eigen::Vector3d& m) const {
  const double s = d.norm();
  const double penalty_slope =
      overlap_penalty(system_.penalty, radius_, s * radius_).derivative * radius_ / energy_scale_;
  const Eigen::Vector3d d0(rest_, 0.0, 0.0);
  return magnetic_gradient(d, m) + (k12_ * (s - rest_) + penalty_slope) * (d / s) +
         0.5 * k0_ * (d - d0);
}

Eigen::Matrix3d PairEnergy::scaled_hessian(const Eigen::Vector3d& d) const {
  constexpr double kStep = 1e-6;  // the magnetic energy varies on the scale of R
  Eigen::Matrix3d h;
  for (int i = 0; i < 3; ++i) {
    Eigen::Vector3d dp = d;
    Eigen::Vector3d dm = d;
    dp(i) += kStep;
    dm(i) -= kStep;
    h.col(i) =
        (magnetic_gradient(dp, magnetization(dp).m) - magnetic_gradient(dm, magnetization(dm).m)) /
        (2.0 * kStep);
  }
  h = 0.5 * (h + h.transpose()).eval();
  // Radial terms f(|d|): Hessian f'' n n^T + (f'/S)(I - n n^T).
  const double s = d.norm();
  const Eigen::Vector3d n = d / s;
  const PenaltyValue p = overlap_penalty(system_.penalty, radius_, s * radius_);
  const double f1 = k12_ * (s - rest_) + p.derivative * radius_ / energy_scale_;
  const double f2 = k12_ + p.second_derivative * radius_ * radius_ / energy_scale_;
  const Eigen::Matrix3d nn = n * n.transpose();
  h += f2 * nn + (f1 / s) * (Eigen::Matrix3d::Identity() - nn);
  h += 0.5 * k0_ * Eigen::Matrix3d::Identity();
  return h;
}

EnergyBreakdown PairEnergy::breakdown(const Eigen::Vector3d& d) const {
  EnergyBreakdown e = scaled_terms(d, magnetization(d));
  for (double* term : {&e.zeeman, &e.dipole, &e.self, &e.spring, &e.anchor, &e.penalty}) {
    *term *= energy_scale_;
  }
  return e;
}

}  // namespace mresim::pair
