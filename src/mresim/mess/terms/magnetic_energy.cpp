#include "mresim/mess/terms/magnetic_energy.hpp"

#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>

#include "mresim/core/constants.hpp"
#include "mresim/mess/magnetization/particle_response.hpp"

namespace mresim::magnetism {
namespace {

void check_pairs(const char* who, const PairList& pairs, Eigen::Index particle_count) {
  for (const ParticlePair& p : pairs) {
    if (p.i < 0 || p.j < 0 || p.i >= particle_count || p.j >= particle_count) {
      throw std::invalid_argument(std::string(who) + ": pair index out of range");
    }
  }
}

void check_shapes(const char* who, const Eigen::Matrix3Xd& centres, const Eigen::Matrix3Xd& M) {
  if (centres.cols() != M.cols()) {
    throw std::invalid_argument(std::string(who) + ": " + std::to_string(centres.cols()) +
                                " centres but " + std::to_string(M.cols()) + " magnetizations");
  }
}

}  // namespace

double WcaParameters::r_cut() const { return std::pow(2.0, 1.0 / 6.0) * r_min; }

WcaParameters WcaParameters::from_radius(double radius, double ms_scale, double gap) {
  if (!(std::isfinite(radius) && radius > 0.0)) {
    throw std::invalid_argument("WcaParameters: radius must be finite and > 0");
  }
  if (!(std::isfinite(ms_scale) && ms_scale > 0.0)) {
    throw std::invalid_argument("WcaParameters: Ms for the WCA scale must be finite and > 0");
  }
  if (!(std::isfinite(gap) && gap >= 0.0)) {
    throw std::invalid_argument("WcaParameters: gap must be finite and >= 0");
  }
  WcaParameters p;
  // Section 4.2.4: E_max = mu0 pi Ms^2 R^3 / 72, r_min = 2R + 100 nm.
  p.e_max = kMu0 * std::numbers::pi * ms_scale * ms_scale * radius * radius * radius / 72.0;
  p.r_min = 2.0 * radius + gap;
  return p;
}

MagneticModel MagneticModel::make(const MagneticParticles& particles,
                                  const Eigen::Vector3d& applied_field, double wca_ms) {
  particles.validate();
  MagneticModel model;
  model.particles = particles;
  model.applied_field = applied_field;
  model.wca = WcaParameters::from_radius(particles.radius, wca_ms > 0.0 ? wca_ms : particles.Ms);
  return model;
}

// ---------------------------------------------------------------------------- Zeeman (4.70)

double zeeman_energy(const MagneticModel& model, const Eigen::Matrix3Xd& centres,
                     const Eigen::Matrix3Xd& M) {
  check_shapes("zeeman_energy", centres, M);
  double sum = 0.0;
  for (Eigen::Index i = 0; i < M.cols(); ++i) sum += M.col(i).dot(model.applied_field);
  return -kMu0 * model.particles.volume() * sum;
}

Eigen::Matrix3Xd zeeman_gradient(const MagneticModel& /*model*/, const Eigen::Matrix3Xd& centres,
                                 const Eigen::Matrix3Xd& M) {
  check_shapes("zeeman_gradient", centres, M);
  // A uniform H_ext exerts no force on a dipole (eq. 4.77 with grad B_ext = 0).
  return Eigen::Matrix3Xd::Zero(3, centres.cols());
}

// ------------------------------------------------------------------ dipole-dipole (4.71, 4.78)

double dipole_energy(const MagneticModel& model, const PairList& pairs, const Eigen::Matrix3Xd& M) {
  check_pairs("dipole_energy", pairs, M.cols());
  const double volume = model.particles.volume();
  double sum = 0.0;
  for (const ParticlePair& p : pairs) {
    const Eigen::Vector3d a = volume * M.col(p.i);  // moments
    const Eigen::Vector3d b = volume * M.col(p.j);
    const double r2 = p.r.squaredNorm();
    const double r = std::sqrt(r2);
    // Eq. 4.71 for one pair: -mu0 m_i . H_dip(r_ij, m_j)
    //   = (mu0 / 4 pi) [m_i . m_j / r^3 - 3 (m_i . r)(m_j . r) / r^5].
    sum += (a.dot(b) - 3.0 * a.dot(p.r) * b.dot(p.r) / r2) / (r2 * r);
  }
  return kMu0 / (4.0 * std::numbers::pi) * sum;
}

Eigen::Matrix3Xd dipole_gradient(const MagneticModel& model, const PairList& pairs,
                                 const Eigen::Matrix3Xd& M) {
  check_pairs("dipole_gradient", pairs, M.cols());
  const double volume = model.particles.volume();
  Eigen::Matrix3Xd gradient = Eigen::Matrix3Xd::Zero(3, M.cols());
  for (const ParticlePair& p : pairs) {
    const Eigen::Vector3d a = volume * M.col(p.i);
    const Eigen::Vector3d b = volume * M.col(p.j);
    const double r2 = p.r.squaredNorm();
    const double r = std::sqrt(r2);
    const double ar = a.dot(p.r);
    const double br = b.dot(p.r);
    // dE/dr_ij = -F_ij of eq. 4.78:
    //   -3 mu0 / (4 pi r^5) [(m_i.r) m_j + (m_j.r) m_i + (m_i.m_j) r - 5 (m_i.r)(m_j.r) r / r^2].
    const Eigen::Vector3d g = -3.0 * kMu0 / (4.0 * std::numbers::pi * r2 * r2 * r) *
                              (ar * b + br * a + (a.dot(b) - 5.0 * ar * br / r2) * p.r);
    // r_ij = r_i - r_j (+ image shift): +g on i, -g on j (cancels for a self-image).
    gradient.col(p.i) += g;
    gradient.col(p.j) -= g;
  }
  return gradient;
}

double dipole_energy(const MagneticModel& model, const Eigen::Matrix3Xd& centres,
                     const Eigen::Matrix3Xd& M) {
  check_shapes("dipole_energy", centres, M);
  return dipole_energy(model, OpenBoundary{}.pairs(centres), M);
}

Eigen::Matrix3Xd dipole_gradient(const MagneticModel& model, const Eigen::Matrix3Xd& centres,
                                 const Eigen::Matrix3Xd& M) {
  check_shapes("dipole_gradient", centres, M);
  return dipole_gradient(model, OpenBoundary{}.pairs(centres), M);
}

// -------------------------------------------------------------------- self-energy (4.73, 4.76)

double self_energy(const MagneticModel& model, const Eigen::Matrix3Xd& centres,
                   const Eigen::Matrix3Xd& M) {
  check_shapes("self_energy", centres, M);
  const MagneticParticles& p = model.particles;
  const double scale = kMu0 * p.Ms * p.Ms * p.volume();  // energies of reduced m = M/Ms
  double sum = 0.0;
  if (model.self_energy == SelfEnergyForm::consistent) {
    // Eq. 4.76 = mu0 Ms^2 V [-|m| - log(1 - |m|)] / chi0 (+ |m|^2 / 6 with demagnetization).
    for (Eigen::Index i = 0; i < M.cols(); ++i) {
      sum += reduced_self_energy(M.col(i) / p.Ms, p.chi0, model.demagnetization);
    }
    return scale * sum;
  }
  // Eq. 4.73 with moments m = V M: mu0 V |M|^2 (Ms + chi0 |H_ext|) / (2 chi0 Ms), i.e.
  // |m|^2 / (2 chi_eff) in reduced units with chi_eff of eq. 4.72.
  const double inverse_chi_eff = (p.Ms + p.chi0 * model.applied_field.norm()) / (p.chi0 * p.Ms);
  for (Eigen::Index i = 0; i < M.cols(); ++i) {
    const double m2 = (M.col(i) / p.Ms).squaredNorm();
    sum += 0.5 * inverse_chi_eff * m2;
    if (model.demagnetization) sum += m2 / 6.0;
  }
  return scale * sum;
}

Eigen::Matrix3Xd self_energy_gradient(const MagneticModel& /*model*/,
                                      const Eigen::Matrix3Xd& centres, const Eigen::Matrix3Xd& M) {
  check_shapes("self_energy_gradient", centres, M);
  // Both forms depend on M (and H_ext) only. With eq. 4.76 and the self-consistent M this is
  // also the full derivative's contribution (envelope theorem, see the header).
  return Eigen::Matrix3Xd::Zero(3, centres.cols());
}

// ------------------------------------------------------------------------------ WCA (4.79)

WcaValue wca_pair(const WcaParameters& wca, double s) {
  WcaValue v;
  const double rc = wca.r_cut();
  if (!(wca.e_max > 0.0) || !(s < rc)) return v;  // zero at and beyond the cut-off
  // q^12 - q^6 + 1/4 = (q^6 - 1/2)^2 with q = r_min/S, and r_min^6 = r_cut^6 / 2, so
  // eq. 4.79 is E = E_max w^2 with w = 2 q^6 - 1 = (r_cut^6 - S^6) / S^6, and
  // r_cut^6 - S^6 = (r_cut - S)(r_cut + S)(r_cut^2 + r_cut S + S^2)(r_cut^2 - r_cut S + S^2):
  // no difference of nearly equal numbers except r_cut - S itself.
  const double s2 = s * s;
  const double s6 = s2 * s2 * s2;
  const double product = (rc + s) * (rc * rc + rc * s + s2) * (rc * rc - rc * s + s2);
  const double w = (rc - s) * product / s6;
  v.energy = wca.e_max * w * w;
  // dE/dS = 2 E_max w dw/dS, dw/dS = -6 r_cut^6 / S^7 = -6 (1 + w) / S; this is eq. 4.80,
  // -4 E_max (12 r_min^12 / S^13 - 6 r_min^6 / S^7), with its second term corrected.
  v.derivative = -12.0 * wca.e_max * w * (1.0 + w) / s;
  return v;
}

double wca_pair_curvature(const WcaParameters& wca, double s) {
  const double rc = wca.r_cut();
  if (!(wca.e_max > 0.0) || !(s < rc)) return 0.0;
  const double s2 = s * s;
  const double w =
      (rc - s) * (rc + s) * (rc * rc + rc * s + s2) * (rc * rc - rc * s + s2) / (s2 * s2 * s2);
  // d/dS of dE/dS = -12 E_max (w + w^2) / S with dw/dS = -6 (1 + w) / S.
  return 12.0 * wca.e_max * (1.0 + w) * (6.0 + 13.0 * w) / s2;
}

double wca_energy(const MagneticModel& model, const PairList& pairs) {
  double sum = 0.0;
  for (const ParticlePair& p : pairs) sum += wca_pair(model.wca, p.r.norm()).energy;
  return sum;
}

Eigen::Matrix3Xd wca_gradient(const MagneticModel& model, const PairList& pairs,
                              int particle_count) {
  check_pairs("wca_gradient", pairs, particle_count);
  Eigen::Matrix3Xd gradient = Eigen::Matrix3Xd::Zero(3, particle_count);
  for (const ParticlePair& p : pairs) {
    const double s = p.r.norm();
    const WcaValue v = wca_pair(model.wca, s);
    if (v.derivative == 0.0) continue;
    const Eigen::Vector3d g = (v.derivative / s) * p.r;
    gradient.col(p.i) += g;
    gradient.col(p.j) -= g;
  }
  return gradient;
}

double wca_energy(const MagneticModel& model, const Eigen::Matrix3Xd& centres) {
  return wca_energy(model, OpenBoundary{}.pairs(centres));
}

Eigen::Matrix3Xd wca_gradient(const MagneticModel& model, const Eigen::Matrix3Xd& centres) {
  return wca_gradient(model, OpenBoundary{}.pairs(centres), static_cast<int>(centres.cols()));
}

// ----------------------------------------------------------------------------------- totals

MagneticEnergyBreakdown magnetic_energies(const MagneticModel& model,
                                          const Eigen::Matrix3Xd& centres,
                                          const Eigen::Matrix3Xd& M) {
  check_shapes("magnetic_energies", centres, M);
  const PairList pairs = OpenBoundary{}.pairs(centres);
  MagneticEnergyBreakdown e;
  e.zeeman = zeeman_energy(model, centres, M);
  e.dipole = dipole_energy(model, pairs, M);
  e.self = self_energy(model, centres, M);
  e.wca = wca_energy(model, pairs);
  return e;
}

Eigen::Matrix3Xd magnetic_gradient(const MagneticModel& model, const Eigen::Matrix3Xd& centres,
                                   const Eigen::Matrix3Xd& M) {
  check_shapes("magnetic_gradient", centres, M);
  const PairList pairs = OpenBoundary{}.pairs(centres);
  // Zeeman and self-energy gradients vanish at fixed M (see the header).
  return dipole_gradient(model, pairs, M) +
         wca_gradient(model, pairs, static_cast<int>(centres.cols()));
}

}  // namespace mresim::magnetism
