#include "mresim/mess/protocols/protocol_runner.hpp"

#include <chrono>
#include <cmath>
#include <stdexcept>
#include <utility>

#include "mresim/app/peak_memory.hpp"
#include "mresim/core/constants.hpp"
#include "mresim/mess/analysis/box_strain.hpp"
#include "mresim/mess/lattice/volume_elements.hpp"
#include "mresim/mess/protocols/load_step_start.hpp"
#include "mresim/mess/protocols/protocol.hpp"
#include "mresim/mess/solvers/leapfrog.hpp"
#include "mresim/mess/solvers/minimiser.hpp"
#include "mresim/mess/solvers/preconditioner.hpp"

namespace mresim::mess_protocol {

namespace mc = mresim::mess_config;
namespace mm = mresim::magnetism;

namespace {

mess::MessSystem make_system(const mc::MessSpec& spec) {
  lattice::Lattice lat = lattice::build_lattice(spec.lattice);
  mm::MagneticParticles particles = spec.particles;
  particles.radius = lat.particle_radius;
  mm::MagneticModel model = mm::MagneticModel::make(particles, Eigen::Vector3d::Zero(),
                                                    spec.profile->wca_scale_ms(particles.Ms));
  model.demagnetization = spec.demagnetization;
  model.self_energy = spec.self_energy;
  mess::MessSettings settings = spec.profile->system_settings();
  settings.magnetization = spec.solver.magnetization;
  settings.magnetization.demagnetization = spec.demagnetization;
  return {std::move(lat), std::move(model), settings, spec.terms};
}

}  // namespace

double system_volume(const lattice::Lattice& lat, const Eigen::Matrix3Xd& x) {
  double volume = 0.0;
  lattice::CellVertices v;
  for (const auto& e : lat.elements) {
    for (int k = 0; k < 8; ++k)
      v[static_cast<std::size_t>(k)] = x.col(e[static_cast<std::size_t>(k)]);
    volume += lattice::cell_volume(v);
  }
  return volume;
}

std::string finished_by_name(const mess::MinimiserResult& result, bool newton) {
  if (result.finished_with_fire) return "fire";
  if (result.slope_only_fallback) return "lbfgs_slope_only";
  if (newton && !result.finished_with_lbfgs) return "newton";
  return "lbfgs";
}

ProtocolRunner::ProtocolRunner(const mc::MessSpec& spec)
    : spec_(spec), steps_(plan_steps(spec)), system_(make_system(spec)) {}

std::size_t ProtocolRunner::slot_of_field(std::size_t field_index) const {
  return spec_.load_step_count() > 1 ? field_index : 0;
}

ProtocolState ProtocolRunner::initial_state() const {
  ProtocolState state;
  const std::size_t fields = spec_.field.values.size();
  state.slots.resize(spec_.load_step_count() > 1 ? fields : 1);
  state.references.resize(spec_.load_step_count() > 1 ? fields : 0);
  state.earlier_load_results.resize(keeps_earlier_load_results() ? fields : 0);
  return state;
}

void ProtocolRunner::park_kept_positions(ProtocolState& state) const {
  if (scratch_directory_.empty() || state.slots.size() <= 1) return;
  if (!state.spill) {
    state.spill = std::make_shared<PositionsSpill>(scratch_directory_, system_.node_count());
  }
  for (SlotState& slot : state.slots) slot.positions.park(state.spill);
  for (KeptPositions& reference : state.references) reference.park(state.spill);
  for (KeptPositions& earlier : state.earlier_load_results) earlier.park(state.spill);
  state.secant_miss.park(state.spill);
  state.earlier_secant_miss.park(state.spill);
}

const SlotState* ProtocolRunner::start_state(const StepSpec& step,
                                             const ProtocolState& state) const {
  if (step.load_index > 0) return &state.slots[slot_of_field(step.field_index)];
  if (step.field_index == 0) return nullptr;  // the initial lattice
  return &state.slots[slot_of_field(step.field_index - 1)];
}

mess::MinimiserOptions ProtocolRunner::minimiser_options() const {
  mess::MinimiserOptions options;
  if (spec_.solver.method == mc::SolverMethod::newton) {
    options.method = mess::MinimiserMethod::newton;
    options.newton_cache = newton_cache_;  // one multigrid for the run's steps
  }
  // "minimiser": L-BFGS with the multilevel preconditioner on large lattices
  // (LbfgsPreconditioner::automatic); "lbfgs" (and newton's L-BFGS fallback): with the
  // rigid-particle preconditioner alone.
  options.lbfgs_preconditioner = spec_.solver.method == mc::SolverMethod::minimiser
                                     ? mess::LbfgsPreconditioner::automatic
                                     : mess::LbfgsPreconditioner::rigid_particles;
  options.preconditioner_cache = preconditioner_cache_;  // one for the run's steps
  options.node_scaling = spec_.solver.node_scaling;
  options.contact_gap = spec_.solver.contact_gap;
  options.preconditioner_reuse = spec_.solver.preconditioner_reuse;
  options.force_tolerance = spec_.solver.minimiser.force_tolerance;
  options.max_iterations = static_cast<int>(spec_.solver.minimiser.max_iterations);
  options.observer = observer_;
  options.distributed = distributed_;
  return options;
}

void ProtocolRunner::set_start(const StepSpec& step, ProtocolState& state) {
  const SlotState* start = start_state(step, state);
  SlotState& slot = state.slots[slot_of_field(step.field_index)];
  if (start == &slot && slot.positions.cols() > 0) {
    // The step replaces the state it starts from (a field loop's one slot; a load step's own):
    // the system takes the positions over instead of copying them, 24 bytes per node less
    // while it relaxes. The slot is written again after the step; if the step throws, the run
    // ends and resumes from its last checkpoint.
    system_.set_positions(slot.positions.take());
  } else {
    system_.set_positions(start != nullptr && start->positions.cols() > 0
                              ? start->positions.load()
                              : system_.lattice().positions);
  }
  // The system holds the start now: every kept array can wait in the scratch file while the
  // step relaxes (the step's own slot and reference are written again after it).
  park_kept_positions(state);
  if (start != nullptr && start->magnetization.cols() > 0) {
    system_.set_magnetizations(start->magnetization);
  }
}

const StepSpec& ProtocolRunner::step_at(std::size_t field_index, std::size_t load_index) const {
  for (const StepSpec& s : steps_) {
    if (s.field_index == field_index && s.load_index == load_index) return s;
  }
  throw std::logic_error("ProtocolRunner: no step at field " + std::to_string(field_index) +
                         " and load value " + std::to_string(load_index));
}

bool ProtocolRunner::keeps_earlier_load_results() const {
  return spec_.keeps_earlier_load_results();
}

bool ProtocolRunner::corrects_load_starts() const {
  return keeps_earlier_load_results() &&
         spec_.solver.load_step_start == mc::LoadStepStart::extrapolated;
}

bool ProtocolRunner::keeps_earlier_field_result() const {
  return spec_.keeps_earlier_field_result();
}

Eigen::Matrix3Xd ProtocolRunner::field_secant_candidate(const StepSpec& step,
                                                        const ProtocolState& state) const {
  if (step.load_index != 0 || step.field_index < 2) return {};
  // x_{f-2}: with one slot the result kept before the slot's; else field f - 2's zero-load
  // result. x_{f-1} is the step's start, which the system holds.
  const KeptPositions& earlier = state.slots.size() == 1
                                     ? state.earlier_field_result
                                     : state.references.at(step.field_index - 2);
  if (earlier.cols() == 0) return {};
  const Eigen::Vector3d& b_previous = step_at(step.field_index - 1, 0).field;
  const Eigen::Vector3d& b_earlier = step_at(step.field_index - 2, 0).field;
  if (b_previous == b_earlier) return {};  // a repeated field: nothing to extrapolate
  return field_secant_start(system_.positions(), earlier.load(), step.field, b_previous, b_earlier);
}

Eigen::Matrix3Xd ProtocolRunner::strain_secant(const StepSpec& step,
                                               const Eigen::Matrix3Xd& previous,
                                               const Eigen::Matrix3Xd& earlier,
                                               const Eigen::Matrix3Xd& zero_load) const {
  const Protocol& protocol = *spec_.protocol;
  const lattice::Lattice& lat = system_.lattice();
  const bool local = earlier.cols() > 0;
  const Eigen::Matrix3Xd& through = local ? earlier : zero_load;
  const StepSpec& previous_step = step_at(step.field_index, step.load_index - 1);
  const StepSpec& before = step_at(step.field_index, local ? step.load_index - 2 : 0);
  return secant_start(previous, through, protocol.measured_strain(lat, step, previous, zero_load),
                      protocol.measured_strain(lat, previous_step, previous, zero_load),
                      protocol.measured_strain(lat, before, through, zero_load));
}

std::vector<Eigen::Matrix3Xd> ProtocolRunner::corrected_secants(
    const StepSpec& step, const ProtocolState& state, const Eigen::Matrix3Xd& secant) const {
  std::vector<Eigen::Matrix3Xd> candidates;
  const auto is_field_before = [&](std::size_t back, std::size_t fields_before) {
    if (state.records.size() < back || step.field_index < fields_before) return false;
    const StepSpec& earlier = state.records[state.records.size() - back].step;
    return earlier.field_index == step.field_index - fields_before &&
           earlier.load_index == step.load_index;
  };
  if (state.secant_miss.cols() == 0 || !is_field_before(1, 1)) return candidates;
  // The previous field's miss, m_{f-1}.
  const Eigen::Matrix3Xd miss = state.secant_miss.load();
  candidates.emplace_back(secant + miss);
  if (state.earlier_secant_miss.cols() == 0 || !is_field_before(2, 2)) return candidates;
  // m_{f-1} + r (m_{f-1} - m_{f-2}): the miss extrapolated in the field, as the field secant
  // extrapolates the states.
  const Eigen::Vector3d& b_previous = state.records.back().step.field;
  const Eigen::Vector3d& b_earlier = state.records[state.records.size() - 2].step.field;
  if (b_previous == b_earlier) return candidates;
  candidates.emplace_back(secant + field_secant_start(miss, state.earlier_secant_miss.load(),
                                                      step.field, b_previous, b_earlier));
  return candidates;
}

bool ProtocolRunner::next_step_takes_miss(std::size_t index) const {
  if (!corrects_load_starts() || index + 1 >= steps_.size()) return false;
  const StepSpec& step = steps_[index];
  const StepSpec& next = steps_[index + 1];
  return step.load_index >= 2 && next.load_index == step.load_index &&
         next.field_index == step.field_index + 1;
}

std::vector<std::size_t> ProtocolRunner::secant_miss_sources(std::size_t index) const {
  if (!next_step_takes_miss(index)) return {};
  const StepSpec& step = steps_[index];
  std::vector<std::size_t> sources = {index, step_at(step.field_index, step.load_index - 1).index};
  if (step.load_index >= 3) {
    sources.push_back(step_at(step.field_index, step.load_index - 2).index);
  }
  sources.push_back(step_at(step.field_index, 0).index);
  return sources;
}

Eigen::Matrix3Xd ProtocolRunner::secant_miss_of(
    std::size_t index, const std::vector<Eigen::Matrix3Xd>& results) const {
  const std::vector<std::size_t> sources = secant_miss_sources(index);
  if (sources.empty() || results.size() != sources.size()) {
    throw std::logic_error("ProtocolRunner::secant_miss_of: step " + std::to_string(index) +
                           " keeps no miss, or the results do not match its sources");
  }
  const StepSpec& step = steps_[index];
  const Eigen::Matrix3Xd& zero_load = results.back();
  // The step's start as run_next_step made it: the previous result with this step's faces.
  Eigen::Matrix3Xd previous = results[1];
  spec_.protocol->load(system_.lattice(), step, zero_load).constraints.apply(previous);
  const Eigen::Matrix3Xd secant = strain_secant(
      step, previous, sources.size() == 4 ? results[2] : Eigen::Matrix3Xd(), zero_load);
  return results[0] - secant;
}

std::string ProtocolRunner::predict_start(const StepSpec& step, const ProtocolState& state,
                                          std::int64_t& evaluations, Eigen::Matrix3Xd& secant) {
  if (start_state(step, state) == nullptr) return step_start::kInitialLattice;
  if (step.load_index == 0) {
    if (spec_.solver.field_step_start != mc::FieldStepStart::extrapolated) {
      return step_start::kPrevious;
    }
    Eigen::Matrix3Xd candidate = field_secant_candidate(step, state);
    if (candidate.cols() == 0) return step_start::kPrevious;
    evaluations += 2;
    return take_if_not_higher(system_, candidate) ? step_start::kFieldSecant
                                                  : step_start::kPredictionRejected;
  }
  const Protocol& protocol = *spec_.protocol;
  const bool first_field = step.field_index == 0;
  if (spec_.solver.load_step_start == mc::LoadStepStart::previous ||
      !protocol.loads_from_zero_load_state() || (step.load_index == 1 && first_field)) {
    return step_start::kPrevious;
  }
  const Eigen::Matrix3Xd zero_load = state.references[step.field_index].load();
  Eigen::Matrix3Xd candidate;
  std::string kind;
  if (step.load_index >= 2) {
    // Through the field's result two load values back, x_{k-2} (the zero-load state at k = 2,
    // and where a checkpoint written before it was kept lacks it).
    const KeptPositions& kept = state.earlier_load_results.at(step.field_index);
    const bool local = step.load_index >= 3 && kept.cols() > 0;
    secant = strain_secant(step, system_.positions(), local ? kept.load() : Eigen::Matrix3Xd(),
                           zero_load);
    std::vector<Eigen::Matrix3Xd> candidates = corrected_secants(step, state, secant);
    if (!candidates.empty()) {
      candidates.insert(candidates.begin(), secant);
      evaluations += 1 + static_cast<std::int64_t>(candidates.size());
      const int taken = take_lowest(system_, candidates);
      if (taken < 0) return step_start::kPredictionRejected;
      return taken == 0 ? step_start::kSecant : step_start::kCorrectedSecant;
    }
    candidate = secant;
    kind = step_start::kSecant;
  } else {
    // Load value 1: the previous field has just relaxed it (its slot) from its reference.
    const std::size_t neighbour = step.field_index - 1;
    const auto response_at = [&](std::size_t field) -> Eigen::Matrix3Xd {
      return state.slots[slot_of_field(field)].positions.load() - state.references[field].load();
    };
    candidate =
        neighbour_field_start(zero_load, state.slots[slot_of_field(neighbour)].positions.load(),
                              state.references[neighbour].load());
    kind = step_start::kNeighbourField;
    if (step.field_index >= 2 && corrects_load_starts()) {
      // The two previous fields' responses, extrapolated in the field (load_step_start.hpp).
      const Eigen::Vector3d& b_previous = step_at(neighbour, 1).field;
      const Eigen::Vector3d& b_earlier = step_at(neighbour - 1, 1).field;
      if (b_previous != b_earlier) {
        std::vector<Eigen::Matrix3Xd> candidates;
        candidates.push_back(std::move(candidate));
        candidates.emplace_back(zero_load + field_secant_start(response_at(neighbour),
                                                               response_at(neighbour - 1),
                                                               step.field, b_previous, b_earlier));
        evaluations += 3;
        const int taken = take_lowest(system_, candidates);
        if (taken < 0) return step_start::kPredictionRejected;
        return taken == 0 ? step_start::kNeighbourField : step_start::kNeighbourFieldSecant;
      }
    }
  }
  // The start with the lower potential, both with this step's faces and field.
  evaluations += 2;
  return take_if_not_higher(system_, candidate) ? kind : step_start::kPredictionRejected;
}

namespace {

// The state's preconditioner anchor (a resumed or extended run's) goes to the cache, and the
// state lets go of it while the step relaxes, so that a new anchor never waits beside it.
void hand_anchor_to_cache(ProtocolState& state, const lattice::Lattice& lat,
                          mess::PreconditionerCache& cache) {
  if (state.preconditioner_anchor != cache.anchor()) {
    cache.restore(lat, state.preconditioner_anchor);
  }
  state.preconditioner_anchor.reset();
}

// After a loaded step's prediction: its start `start`, the field's result at the strain before,
// becomes the earlier point of the field's next strain step's secant
// (ProtocolState::earlier_load_results); nothing where none was kept.
void keep_load_start(const ProtocolRunner& runner, ProtocolState& state, std::size_t field,
                     KeptPositions start) {
  if (start.cols() == 0) return;
  state.earlier_load_results.at(field) = std::move(start);
  runner.park_kept_positions(state);
}

// After a loaded step whose secant `secant` the next step's correction needs (else none): the
// step's result minus it becomes the state's secant miss, the miss before it the earlier one
// (ProtocolState::secant_miss); otherwise the state keeps none.
void keep_secant_miss(const ProtocolRunner& runner, ProtocolState& state,
                      const Eigen::Matrix3Xd& result, const KeptPositions& secant) {
  if (secant.cols() == 0) {
    state.secant_miss = KeptPositions();
    state.earlier_secant_miss = KeptPositions();
    return;
  }
  state.earlier_secant_miss = std::move(state.secant_miss);
  state.secant_miss = Eigen::Matrix3Xd(result - secant.load());
  runner.park_kept_positions(state);
}

// The step's magnetization solves (since `before`) and its final solve; a step converges only
// if that solve did.
void record_magnetization(const mess::MessSystem& system, const mess::MagnetizationStats& before,
                          StepRecord& record) {
  const mess::MagnetizationStats& after = system.magnetization_stats();
  record.magnetization_solves = after.solves - before.solves;
  record.unconverged_magnetization_solves = after.unconverged - before.unconverged;
  // Without particles no magnetization is solved (MessSystem skips it): "none".
  record.magnetization_method =
      system.particle_count() == 0 ? "none" : mm::to_string(after.last.method);
  record.magnetization_iterations = after.last.total_iterations;
  record.magnetization_residual = after.last.residual;
  record.converged = record.converged && (system.particle_count() == 0 || after.last.converged);
}

}  // namespace

void ProtocolRunner::relax(const StepSpec& step, StepRecord& record) {
  if (spec_.solver.method != mc::SolverMethod::leapfrog) {
    const mess::MinimiserResult r = mess::minimise(system_, minimiser_options());
    record.converged = r.converged;
    record.status = to_string(r.status);
    record.iterations = r.iterations;
    record.evaluations = r.evaluations;
    record.krylov_iterations = r.krylov_iterations;
    record.finished_by = finished_by_name(r, spec_.solver.method == mc::SolverMethod::newton);
    record.correction_passes = r.correction_passes;
    if (!r.state_preconditioner.empty()) record.preconditioner = r.state_preconditioner;
    record.max_force = r.max_force;
    record.energies = r.final.energies;
    return;
  }
  mess::LeapfrogOptions options = spec_.profile->leapfrog_options();
  options.time_step = spec_.solver.leapfrog.dt;
  options.steps_per_round = static_cast<int>(spec_.solver.leapfrog.steps_per_round);
  options.max_rounds = static_cast<int>(spec_.solver.leapfrog.max_rounds);
  options.drag = spec_.solver.leapfrog.drag;
  options.observer = observer_;
  // docs/original-code.md#convergence: at zero field and zero load one round may end the step.
  options.first_round_may_end = step.field.norm() < 1e-12 && step.load_value == 0.0;
  const mess::LeapfrogResult r = mess::relax_leapfrog(system_, options);
  record.converged = r.converged;
  record.status = to_string(r.status);
  record.iterations = r.steps;
  record.evaluations = r.steps + 1;
  record.finished_by = "leapfrog";
  record.max_force = r.history.empty() ? 0.0 : r.history.back().mean_abs_acceleration;
  record.energies = r.final.energies;
}

const StepRecord& ProtocolRunner::run_next_step(ProtocolState& state) {
  if (state.next_step >= steps_.size()) {
    throw std::logic_error("ProtocolRunner::run_next_step: no steps left");
  }
  const auto started = std::chrono::steady_clock::now();
  const StepSpec& step = steps_[state.next_step];
  const lattice::Lattice& lat = system_.lattice();
  hand_anchor_to_cache(state, lat, *preconditioner_cache_);

  // Boundary conditions (the protocol's): loaded steps of a protocol that says so are measured
  // from the zero-load state at this field.
  const Protocol& protocol = *spec_.protocol;
  const bool loaded = step.load_index > 0 && protocol.loads_from_zero_load_state();
  // The zero-load reference, read (from memory or the scratch file) where it is needed and not
  // held while the step relaxes: with many fields it may be parked.
  const auto reference_of_field = [&] { return state.references[step.field_index].load(); };
  LoadState load = protocol.load(lat, step, loaded ? reference_of_field() : lat.positions);

  SlotState& slot = state.slots[slot_of_field(step.field_index)];
  // The start, x_{k-1} at this field (a shared copy where it is parked): keep_load_start.
  KeptPositions load_start;
  if (keeps_earlier_load_results() && step.load_index > 0) load_start = slot.positions;
  // With one slot, the field secant of the next field needs this step's start (the previous
  // field's result) after the step, when the slot holds this step's result.
  Eigen::Matrix3Xd start_to_keep;
  if (keeps_earlier_field_result() && slot.positions.cols() > 0) {
    start_to_keep = slot.positions.load();
  }
  system_.set_constraints(std::move(load.constraints));
  system_.set_applied_forces(load.applied_forces);
  set_start(step, state);
  system_.set_applied_field(step.field / kMu0);

  const mess::MagnetizationStats before = system_.magnetization_stats();
  StepRecord record;
  record.step = step;
  std::int64_t prediction_evaluations = 0;
  Eigen::Matrix3Xd secant;
  record.start = predict_start(step, state, prediction_evaluations, secant);
  // Where the next step takes this step's secant miss, the secant waits in the scratch file
  // (where there is one) while the step relaxes.
  KeptPositions kept_secant;
  if (next_step_takes_miss(state.next_step)) kept_secant = std::move(secant);
  if (state.spill) kept_secant.park(state.spill);
  keep_load_start(*this, state, step.field_index, std::move(load_start));
  // The secant has been made: its earlier point is not held while the step relaxes (this step's
  // start takes its place after the step).
  if (keeps_earlier_field_result()) state.earlier_field_result = KeptPositions();
  relax(step, record);
  record.evaluations += prediction_evaluations;

  record_magnetization(system_, before, record);

  record.centres = system_.particle_centres();
  record.magnetization = system_.magnetizations();
  record.system_volume = system_volume(lat, system_.positions());
  record.box_strain = mess_analysis::box_strain(lat, system_.positions());
  record.measured_strain =
      protocol.measured_strain(lat, step, system_.positions(),
                               step.load_index > 0 ? reference_of_field() : system_.positions());

  // Advance the state.
  keep_secant_miss(*this, state, system_.positions(), kept_secant);
  if (keeps_earlier_field_result()) state.earlier_field_result = std::move(start_to_keep);
  slot.positions = system_.positions();
  slot.magnetization = system_.magnetizations();
  if (step.load_index == 0 && !state.references.empty()) {
    state.references[step.field_index] = system_.positions();
  }
  record.wall_time =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  record.peak_resident_memory = app::peak_resident_memory_bytes();
  state.records.push_back(std::move(record));
  state.preconditioner_anchor = preconditioner_cache_->anchor();
  ++state.next_step;
  return state.records.back();
}

void ProtocolRunner::run(ProtocolState& state,
                         const std::function<void(const ProtocolState&)>& after_step) {
  while (state.next_step < steps_.size()) {
    run_next_step(state);
    if (after_step) after_step(state);
  }
}

}  // namespace mresim::mess_protocol
