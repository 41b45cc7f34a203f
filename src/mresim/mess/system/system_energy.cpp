#include "mresim/mess/system/system_energy.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "mresim/mess/profile/model_profile.hpp"
#include "mresim/mess/system/fixed_order.hpp"

namespace mresim::mess {

namespace mm = mresim::magnetism;

MessSystem::MessSystem(lattice::Lattice lattice, mm::MagneticModel model, MessSettings settings)
    : lattice_(std::move(lattice)), model_(std::move(model)), settings_(std::move(settings)) {
  model_.particles.validate();
  if (lattice_.particle_count() > 0 &&
      std::abs(model_.particles.radius - lattice_.particle_radius) >
          1e-12 * lattice_.particle_radius) {
    throw std::invalid_argument("MessSystem: the magnetic model's particle radius (" +
                                std::to_string(model_.particles.radius) +
                                " m) differs from the lattice's (" +
                                std::to_string(lattice_.particle_radius) + " m)");
  }
  if (!(settings_.elastic.volume_force_factor > 0.0)) {
    throw std::invalid_argument("MessSystem: volume_force_factor must be > 0");
  }
  if (!(settings_.resolve_distance >= 0.0)) {
    throw std::invalid_argument("MessSystem: resolve_distance must be >= 0");
  }
  model_.self_energy = mm::SelfEnergyForm::consistent;  // eq. 4.76 in the total (envelope)
  settings_.magnetization.demagnetization = model_.demagnetization;
  settings_.magnetization.validate();
  elastic_ = ElasticTerms(lattice_, settings_.elastic);
  positions_ = lattice_.positions;
  constraints_ = BoundaryConstraints::none(lattice_.node_count());
  M_ = Eigen::Matrix3Xd::Zero(3, static_cast<Eigen::Index>(lattice_.particle_count()));
}

MessSystem MessSystem::make(lattice::Lattice lattice, const Eigen::Vector3d& applied_field,
                            const ModelProfile& profile, const mm::MagneticParticles& particles) {
  mm::MagneticParticles p = particles;
  p.radius = lattice.particle_radius > 0.0 ? lattice.particle_radius : p.radius;
  mm::MagneticModel model = mm::MagneticModel::make(p, applied_field, profile.wca_scale_ms(p.Ms));
  return {std::move(lattice), std::move(model), profile.system_settings()};
}

void MessSystem::set_applied_field(const Eigen::Vector3d& applied_field) {
  model_.applied_field = applied_field;
  field_changed_ = true;
}

void MessSystem::set_positions(const Eigen::Matrix3Xd& positions) {
  if (positions.cols() != lattice_.node_count()) {
    throw std::invalid_argument("MessSystem::set_positions: expected " +
                                std::to_string(lattice_.node_count()) + " columns");
  }
  positions_ = positions;
  constraints_.apply(positions_);
}

void MessSystem::set_constraints(BoundaryConstraints constraints) {
  constraints.validate(lattice_.node_count());
  if (constraints.fixed.empty()) {
    BoundaryConstraints none = BoundaryConstraints::none(lattice_.node_count());
    none.rigid_groups = std::move(constraints.rigid_groups);
    constraints = std::move(none);
  }
  constraints_ = std::move(constraints);
  constraints_.apply(positions_);
}

void MessSystem::set_applied_forces(const Eigen::Matrix3Xd& forces) {
  if (forces.cols() != 0 && forces.cols() != lattice_.node_count()) {
    throw std::invalid_argument("MessSystem::set_applied_forces: expected 0 or " +
                                std::to_string(lattice_.node_count()) + " columns");
  }
  applied_forces_ = forces;
}

void MessSystem::set_magnetizations(const Eigen::Matrix3Xd& M) {
  if (M.cols() != static_cast<Eigen::Index>(lattice_.particle_count())) {
    throw std::invalid_argument("MessSystem::set_magnetizations: expected one column per particle");
  }
  M_ = M;
  has_history_ = true;
}

Eigen::Matrix3Xd MessSystem::particle_centres() const {
  return particle_centres(settings_.centre_rule);
}

Eigen::Matrix3Xd MessSystem::particle_centres(CentreRule rule) const {
  const auto np = static_cast<Eigen::Index>(lattice_.particle_count());
  Eigen::Matrix3Xd c(3, np);
  for (Eigen::Index p = 0; p < np; ++p) {
    const auto& nodes = lattice_.particle_nodes[static_cast<std::size_t>(p)];
    // The first 8 nodes are the centre voxel's corners (lattice/spheres.hpp).
    const std::size_t count = rule == CentreRule::centre_voxel ? 8 : nodes.size();
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (std::size_t k = 0; k < count; ++k) sum += positions_.col(nodes[k]);
    c.col(p) = sum / static_cast<double>(count);
  }
  return c;
}

Eigen::Matrix3Xd MessSystem::particle_bounding_box_centres() const {
  const auto np = static_cast<Eigen::Index>(lattice_.particle_count());
  Eigen::Matrix3Xd c(3, np);
  for (Eigen::Index p = 0; p < np; ++p) {
    const auto& nodes = lattice_.particle_nodes[static_cast<std::size_t>(p)];
    Eigen::Vector3d lo = positions_.col(nodes[0]);
    Eigen::Vector3d hi = lo;
    for (const std::int32_t n : nodes) {
      lo = lo.cwiseMin(positions_.col(n));
      hi = hi.cwiseMax(positions_.col(n));
    }
    c.col(p) = 0.5 * (lo + hi);
  }
  return c;
}

const mm::MagnetizationResult& MessSystem::solve_magnetization() {
  const Eigen::Matrix3Xd centres = particle_centres();
  if (centres.cols() == 0) {
    stats_.last = mm::MagnetizationResult{};
    stats_.last.converged = true;
    field_changed_ = false;
    return stats_.last;
  }
  const Eigen::Matrix3Xd history = has_history_ ? M_ : Eigen::Matrix3Xd(3, 0);
  mm::MagnetizationOptions options = settings_.magnetization;
  options.demagnetization = model_.demagnetization;  // the law must match the energies
  stats_.last =
      mm::solve_magnetization(centres, model_.particles, model_.applied_field, history, options);
  ++stats_.solves;
  if (!stats_.last.converged) ++stats_.unconverged;
  stats_.total_iterations += stats_.last.total_iterations;
  ++stats_.by_method[static_cast<std::size_t>(stats_.last.method)];
  M_ = stats_.last.M;
  has_history_ = true;
  field_changed_ = false;
  last_solve_centres_ = centres;
  return stats_.last;
}

void MessSystem::maybe_update_magnetization() {
  if (lattice_.particle_count() == 0) return;
  switch (settings_.magnetization_update) {
    case MagnetizationUpdate::manual:
      return;
    case MagnetizationUpdate::every_evaluation:
      (void)solve_magnetization();
      return;
    case MagnetizationUpdate::on_displacement: {
      bool needed = field_changed_ || last_solve_centres_.cols() != M_.cols();
      if (!needed) {
        const double moved = (particle_centres() - last_solve_centres_).colwise().norm().maxCoeff();
        needed = moved > settings_.resolve_distance * lattice_.element_length;
      }
      if (needed) (void)solve_magnetization();
      return;
    }
  }
}

MessEnergies MessSystem::magnetic_and_load_energies(const Eigen::Matrix3Xd& centres) const {
  MessEnergies e;
  if (centres.cols() > 0) {
    const mm::MagneticEnergyBreakdown b = mm::magnetic_energies(model_, centres, M_);
    e.zeeman = b.zeeman;
    e.dipole = b.dipole;
    e.self = b.self;
    e.wca = b.wca;
    mm::MagneticModel linearized = model_;
    linearized.self_energy = mm::SelfEnergyForm::linearized;
    e.self_linearized = mm::self_energy(linearized, centres, M_);
  }
  if (applied_forces_.cols() > 0) {
    const Eigen::Matrix3Xd& x0 = lattice_.positions;
    e.load = -detail::fixed_order_sum(lattice_.node_count(), [&](std::int64_t n) {
      return applied_forces_.col(n).dot(positions_.col(n) - x0.col(n));
    });
  }
  return e;
}

MessEnergies MessSystem::energies() const {
  MessEnergies e = magnetic_and_load_energies(particle_centres());
  const ElasticEnergies el = elastic_.evaluate(lattice_, positions_, nullptr);
  e.springs = el.springs;
  e.volume = el.volume;
  return e;
}

Eigen::Matrix3Xd MessSystem::centre_gradient() const {
  const Eigen::Matrix3Xd centres = particle_centres();
  if (centres.cols() == 0) return Eigen::Matrix3Xd::Zero(3, 0);
  return mm::magnetic_gradient(model_, centres, M_);
}

Evaluation MessSystem::evaluate(Eigen::Matrix3Xd* gradient) {
  if (!(settings_.elastic.volume_force_factor > 0.0)) {
    throw std::invalid_argument("MessSystem: volume_force_factor must be > 0");
  }
  elastic_.set_settings(settings_.elastic);  // settings() may have been edited
  maybe_update_magnetization();
  const Eigen::Matrix3Xd centres = particle_centres();
  Evaluation out;
  out.energies = magnetic_and_load_energies(centres);
  const ElasticEnergies el = elastic_.evaluate(lattice_, positions_, gradient);
  out.energies.springs = el.springs;
  out.energies.volume = el.volume;
  const MessEnergies& e = out.energies;
  const double factor = settings_.elastic.volume_force_factor;
  out.potential = e.total() + (factor - 1.0) * e.volume;
  out.magnitude = el.springs_rounding + factor * el.volume_rounding + std::abs(e.springs) +
                  factor * std::abs(e.volume) + std::abs(e.zeeman) + std::abs(e.dipole) +
                  std::abs(e.self) + std::abs(e.wca) + std::abs(e.load);
  if (gradient == nullptr) return out;

  if (applied_forces_.cols() > 0) *gradient -= applied_forces_;
  if (centres.cols() > 0) {
    // Dipole (eq. 4.78) + WCA (eq. 4.80) at fixed M, shared equally by the particle's nodes.
    const Eigen::Matrix3Xd gc = mm::magnetic_gradient(model_, centres, M_);
    for (Eigen::Index p = 0; p < centres.cols(); ++p) {
      const auto& nodes = lattice_.particle_nodes[static_cast<std::size_t>(p)];
      const Eigen::Vector3d share = gc.col(p) / static_cast<double>(nodes.size());
      for (const std::int32_t n : nodes) gradient->col(n) += share;
    }
  }
  return out;
}

}  // namespace mresim::mess
