#include "mresim/mess/system/system_energy.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>

#include "mresim/mess/profile/model_profile.hpp"
#include "mresim/mess/system/fixed_order.hpp"

namespace mresim::mess {

namespace mm = mresim::magnetism;

MessSystem::MessSystem(lattice::Lattice lattice, mm::MagneticModel model, MessSettings settings,
                       std::vector<TermSpec> terms)
    : lattice_(std::move(lattice)),
      model_(std::move(model)),
      settings_(std::move(settings)),
      term_specs_(std::move(terms)) {
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
  build_terms();
  positions_ = lattice_.positions;
  constraints_ = BoundaryConstraints::none(lattice_.node_count());
  M_ = Eigen::Matrix3Xd::Zero(3, static_cast<Eigen::Index>(lattice_.particle_count()));
}

MessSystem::MessSystem(const MessSystem& other)
    : lattice_(other.lattice_),
      model_(other.model_),
      settings_(other.settings_),
      term_specs_(other.term_specs_),
      positions_(other.positions_),
      constraints_(other.constraints_),
      applied_forces_(other.applied_forces_),
      M_(other.M_),
      has_history_(other.has_history_),
      field_changed_(other.field_changed_),
      last_solve_centres_(other.last_solve_centres_),
      stats_(other.stats_) {
  build_terms();
}

MessSystem& MessSystem::operator=(const MessSystem& other) {
  if (this != &other) *this = MessSystem(other);
  return *this;
}

void MessSystem::build_terms() {
  terms_ = make_energy_terms({lattice_, model_, settings_}, term_specs_);
  auto labels = std::make_shared<TermLabels>();
  for (const auto& t : terms_) {
    labels->push_back({std::string(t->name()), std::string(t->equation()), std::string(t->title()),
                       t->in_total()});
  }
  labels_ = std::move(labels);
}

MessSystem MessSystem::make(lattice::Lattice lattice, const Eigen::Vector3d& applied_field,
                            const ModelProfile& profile, const mm::MagneticParticles& particles,
                            std::vector<TermSpec> terms) {
  mm::MagneticParticles p = particles;
  p.radius = lattice.particle_radius > 0.0 ? lattice.particle_radius : p.radius;
  mm::MagneticModel model = mm::MagneticModel::make(p, applied_field, profile.wca_scale_ms(p.Ms));
  return {std::move(lattice), std::move(model), profile.system_settings(), std::move(terms)};
}

void MessSystem::set_applied_field(const Eigen::Vector3d& applied_field) {
  model_.applied_field = applied_field;
  field_changed_ = true;
}

void MessSystem::set_positions(const Eigen::Matrix3Xd& positions) {
  set_positions(Eigen::Matrix3Xd(positions));
}

void MessSystem::set_positions(Eigen::Matrix3Xd&& positions) {
  if (positions.cols() != lattice_.node_count()) {
    throw std::invalid_argument("MessSystem::set_positions: expected " +
                                std::to_string(lattice_.node_count()) + " columns");
  }
  positions_ = std::move(positions);
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
  return particle_centres_at(positions_, rule);
}

Eigen::Matrix3Xd MessSystem::particle_centres_at(const Eigen::Matrix3Xd& x, CentreRule rule) const {
  const auto np = static_cast<Eigen::Index>(lattice_.particle_count());
  Eigen::Matrix3Xd c(3, np);
  for (Eigen::Index p = 0; p < np; ++p) {
    const auto& nodes = lattice_.particle_nodes[static_cast<std::size_t>(p)];
    // The first 8 nodes are the centre voxel's corners (lattice/spheres.hpp).
    const std::size_t count = rule == CentreRule::centre_voxel ? 8 : nodes.size();
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (std::size_t k = 0; k < count; ++k) sum += x.col(nodes[k]);
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
  return solve_magnetization_at(particle_centres());
}

const mm::MagnetizationResult& MessSystem::solve_magnetization_at(const Eigen::Matrix3Xd& centres) {
  if (centres.cols() != static_cast<Eigen::Index>(lattice_.particle_count())) {
    throw std::invalid_argument(
        "MessSystem::solve_magnetization_at: expected one column per particle");
  }
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
  if (lattice_.particle_count() == 0 ||
      settings_.magnetization_update == MagnetizationUpdate::manual) {
    return;
  }
  update_magnetization_at(particle_centres());
}

void MessSystem::update_magnetization_at(const Eigen::Matrix3Xd& centres) {
  if (lattice_.particle_count() == 0) return;
  switch (settings_.magnetization_update) {
    case MagnetizationUpdate::manual:
      return;
    case MagnetizationUpdate::every_evaluation:
      (void)solve_magnetization_at(centres);
      return;
    case MagnetizationUpdate::on_displacement: {
      bool needed = field_changed_ || last_solve_centres_.cols() != M_.cols();
      if (!needed) {
        const double moved = (centres - last_solve_centres_).colwise().norm().maxCoeff();
        needed = moved > settings_.resolve_distance * lattice_.element_length;
      }
      if (needed) (void)solve_magnetization_at(centres);
      return;
    }
  }
}

template <class F>
auto MessSystem::with_state(F&& f) const {
  return with_state_at(positions_, std::forward<F>(f));
}

template <class F>
auto MessSystem::with_state_at(const Eigen::Matrix3Xd& x, F&& f) const {
  const Eigen::Matrix3Xd centres = particle_centres_at(x, settings_.centre_rule);
  // One pair list for all pair terms (dipole, WCA), as magnetic_energies() builds it.
  const mm::PairList pairs =
      centres.cols() > 0 ? mm::OpenBoundary{}.pairs(centres) : mm::PairList{};
  const TermState state{lattice_, x, centres, M_, model_, applied_forces_, settings_, pairs};
  return f(state);
}

MessEnergies MessSystem::energies() const {
  return with_state([&](const TermState& state) {
    MessEnergies e(labels_);
    for (std::size_t i = 0; i < terms_.size(); ++i) {
      e.value(i) = terms_[i]->evaluate(state, nullptr).energy;
    }
    return e;
  });
}

Eigen::Matrix3Xd MessSystem::centre_gradient() const {
  return with_state([&](const TermState& state) {
    TermGradient g = TermGradient::zero(state);
    for (const auto& t : terms_) {
      if (t->in_total()) (void)t->evaluate(state, &g);
    }
    return Eigen::Matrix3Xd(g.centres);
  });
}

namespace {

// Adds dE/dc_p / n_p to every node of particle p (the rule of the header).
void spread_centre_terms(const lattice::Lattice& lat, const Eigen::Matrix3Xd& gc,
                         Eigen::Matrix3Xd& nodes) {
  for (Eigen::Index p = 0; p < gc.cols(); ++p) {
    const auto& members = lat.particle_nodes[static_cast<std::size_t>(p)];
    const Eigen::Vector3d share = gc.col(p) / static_cast<double>(members.size());
    for (const std::int32_t n : members) nodes.col(n) += share;
  }
}

}  // namespace

Evaluation evaluation_from_terms(const std::vector<std::unique_ptr<EnergyTerm>>& terms,
                                 const std::shared_ptr<const TermLabels>& labels,
                                 const std::vector<TermValue>& values, const TermState& state) {
  Evaluation out;
  out.energies = MessEnergies(labels);
  // The magnitude is one sum in list order: first every rounding scale, then every |E|,
  // each times its force factor (the order of the fixed fields before the term list).
  double magnitude = 0.0;
  double extra = 0.0;  // sum (force_factor - 1) E over the terms whose factor is not 1
  std::vector<double> factors(terms.size(), 0.0);
  for (std::size_t i = 0; i < terms.size(); ++i) {
    const EnergyTerm& t = *terms[i];
    out.energies.value(i) = values[i].energy;
    if (!t.in_total()) continue;
    factors[i] = t.force_factor(state);
    magnitude += factors[i] * values[i].rounding;
    // Never (1 - 1) x inf: the self-energy may be +inf.
    if (factors[i] != 1.0) extra += (factors[i] - 1.0) * values[i].energy;
  }
  for (std::size_t i = 0; i < terms.size(); ++i) {
    if (terms[i]->in_total()) magnitude += factors[i] * std::abs(out.energies.value(i));
  }
  out.potential = extra == 0.0 ? out.energies.total() : out.energies.total() + extra;
  out.magnitude = magnitude;
  return out;
}

Evaluation MessSystem::evaluate(Eigen::Matrix3Xd* gradient) {
  if (!(settings_.elastic.volume_force_factor > 0.0)) {
    throw std::invalid_argument("MessSystem: volume_force_factor must be > 0");
  }
  maybe_update_magnetization();
  return with_state([&](const TermState& state) {
    TermGradient g;
    if (gradient != nullptr) {
      g.nodes = std::move(*gradient);  // reuse the caller's storage
      g.nodes.resize(3, lattice_.node_count());
      double* zero = g.nodes.data();  // zeroed on both cores: 24 bytes per node
      detail::for_each_block(g.nodes.size(), [zero](std::int64_t begin, std::int64_t end) {
        std::fill(zero + begin, zero + end, 0.0);
      });
      g.centres.setZero(3, state.centres.cols());
    }
    std::vector<TermValue> values(terms_.size());
    for (std::size_t i = 0; i < terms_.size(); ++i) {
      const EnergyTerm& t = *terms_[i];
      values[i] = t.evaluate(state, t.in_total() && gradient != nullptr ? &g : nullptr);
    }
    Evaluation out = evaluation_from_terms(terms_, labels_, values, state);
    if (gradient != nullptr) {
      spread_centre_terms(lattice_, g.centres, g.nodes);
      *gradient = std::move(g.nodes);
    }
    return out;
  });
}

Eigen::Matrix3Xd MessSystem::hessian_product(const Eigen::Matrix3Xd& v) const {
  if (v.cols() != lattice_.node_count()) {
    throw std::invalid_argument("MessSystem::hessian_product: expected " +
                                std::to_string(lattice_.node_count()) + " columns");
  }
  return with_state([&](const TermState& state) {
    // The centres' direction under the centre rule (the first 8 nodes: the centre voxel).
    TermGradient direction{v, Eigen::Matrix3Xd::Zero(3, state.centres.cols())};
    for (Eigen::Index p = 0; p < state.centres.cols(); ++p) {
      const auto& nodes = lattice_.particle_nodes[static_cast<std::size_t>(p)];
      const std::size_t count =
          settings_.centre_rule == CentreRule::centre_voxel ? 8 : nodes.size();
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      for (std::size_t k = 0; k < count; ++k) sum += v.col(nodes[k]);
      direction.centres.col(p) = sum / static_cast<double>(count);
    }
    TermGradient out = TermGradient::zero(state);
    for (const auto& t : terms_) {
      if (t->in_total() && t->hessian_kind() != HessianKind::zero) {
        t->add_hessian_product(state, direction, out);
      }
    }
    spread_centre_terms(lattice_, out.centres, out.nodes);
    return Eigen::Matrix3Xd(out.nodes);
  });
}

Eigen::SparseMatrix<double> MessSystem::elastic_hessian() const {
  std::vector<Eigen::Triplet<double>> entries;
  TripletSink sink(entries);
  add_elastic_hessian_blocks(sink);
  const Eigen::Index n = 3 * lattice_.node_count();
  Eigen::SparseMatrix<double> h(n, n);
  h.setFromTriplets(entries.begin(), entries.end());
  return h;
}

void MessSystem::add_elastic_hessian_blocks(HessianBlockSink& sink) const {
  add_elastic_hessian_blocks(sink, positions_);
}

void MessSystem::add_elastic_hessian_blocks(HessianBlockSink& sink,
                                            const Eigen::Matrix3Xd& at) const {
  if (at.cols() != lattice_.node_count()) {
    throw std::invalid_argument("MessSystem::add_elastic_hessian_blocks: expected " +
                                std::to_string(lattice_.node_count()) + " columns");
  }
  with_state_at(at, [&](const TermState& state) {
    for (const auto& t : terms_) {
      if (t->in_total() && t->has_hessian_entries()) t->add_hessian_blocks(state, sink);
    }
    return 0;
  });
}

Eigen::Matrix3Xd MessSystem::elastic_hessian_product(const Eigen::Matrix3Xd& v) const {
  if (v.cols() != lattice_.node_count()) {
    throw std::invalid_argument("MessSystem::elastic_hessian_product: expected " +
                                std::to_string(lattice_.node_count()) + " columns");
  }
  return with_state([&](const TermState& state) {
    const TermGradient direction{v, Eigen::Matrix3Xd::Zero(3, state.centres.cols())};
    TermGradient out = TermGradient::zero(state);
    for (const auto& t : terms_) {
      if (t->in_total() && t->has_hessian_entries()) t->add_hessian_product(state, direction, out);
    }
    return Eigen::Matrix3Xd(out.nodes);
  });
}

Eigen::MatrixXd MessSystem::reduced_centre_hessian() const {
  const Eigen::Matrix3Xd c0 = particle_centres();
  const Eigen::Index np = c0.cols();
  Eigen::MatrixXd k = Eigen::MatrixXd::Zero(3 * np, 3 * np);
  if (np == 0) return k;
  mm::MagnetizationOptions options = settings_.magnetization;
  options.demagnetization = model_.demagnetization;
  options.atol = std::min(options.atol, 1e-13);
  options.rtol = std::min(options.rtol, 1e-13);
  const Eigen::Matrix3Xd history = has_history_ ? M_ : Eigen::Matrix3Xd(3, 0);
  // The centre gradient of the centre terms at centres c, M solved there.
  const auto centre_gradient_at = [&](const Eigen::Matrix3Xd& c) {
    const mm::MagnetizationResult m =
        mm::solve_magnetization(c, model_.particles, model_.applied_field, history, options);
    const mm::PairList pairs = mm::OpenBoundary{}.pairs(c);
    const TermState state{lattice_, positions_, c, m.M, model_, applied_forces_, settings_, pairs};
    TermGradient g = TermGradient::zero(state);
    for (const auto& t : terms_) {
      if (t->in_total() && !t->has_hessian_entries()) (void)t->evaluate(state, &g);
    }
    return Eigen::Matrix3Xd(g.centres);
  };
  const double h = 1e-4 * lattice_.element_length;
  for (Eigen::Index p = 0; p < np; ++p) {
    for (int a = 0; a < 3; ++a) {
      Eigen::Matrix3Xd plus = c0;
      Eigen::Matrix3Xd minus = c0;
      plus(a, p) += h;
      minus(a, p) -= h;
      const Eigen::Matrix3Xd difference = centre_gradient_at(plus) - centre_gradient_at(minus);
      k.col(3 * p + a) = Eigen::Map<const Eigen::VectorXd>(difference.data(), 3 * np) / (2.0 * h);
    }
  }
  return 0.5 * (k + k.transpose());
}

}  // namespace mresim::mess
