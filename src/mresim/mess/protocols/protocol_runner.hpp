#pragma once

// Runs the steps of a 3D protocol (Section 4.2.7): builds the system from the run file's
// MessSpec, and for every step sets the field and the boundary conditions, starts from the
// state Section 4.2.7 and docs/original-code.md#step-order prescribe, relaxes (minimiser or the
// dissertation's leapfrog) and records what the outputs need.
//
// Where a step starts (positions and magnetizations; velocities are zero):
//  - the first load value (and every step of hysteresis and magnetostriction runs): from the
//    previous step (the previous field), the first from the initial lattice with no
//    magnetization history;
//  - later load values: from the result of the previous load value at the same field (the
//    original's output n - (F - 1)). Unlike the original this also holds with a single field.
//    Strain runs with solver.load_step_start = "extrapolated" (the default) move that state to a
//    prediction of the new one first (load_step_start.hpp); the relaxation ends at the same
//    tolerance.
//  - field steps from the third field on, with solver.field_step_start = "extrapolated" (the
//    default): from the secant through the two previous fields' results (load_step_start.hpp),
//    where its potential is not higher.
// The zero-load result at each field is the reference configuration of the loaded steps at that
// field (strain values are applied relative to it; a stress run's strain is measured from it).
//
// The whole evolving state (ProtocolState) is plain data, so a checkpoint (checkpoint.hpp) can
// save it after any step and a resumed run continues bit for bit as the uninterrupted one.

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "mresim/mess/protocols/kept_positions.hpp"
#include "mresim/mess/protocols/step_plan.hpp"
#include "mresim/mess/run_file/mess_spec.hpp"
#include "mresim/mess/solvers/newton.hpp"
#include "mresim/mess/solvers/preconditioner_cache.hpp"
#include "mresim/mess/solvers/relaxation_observer.hpp"
#include "mresim/mess/system/system_energy.hpp"

namespace mresim::mess_protocol {

// What one converged (or not) step leaves for the outputs.
// What finished a relaxation: "newton", "lbfgs", "lbfgs_slope_only" (L-BFGS on the seed's own
// forces with the slope-only line search, after the correction passes gave up), "fire" (the
// last fallback) or "leapfrog".
std::string finished_by_name(const mess::MinimiserResult& result, bool newton);

struct StepRecord {
  StepSpec step;
  mess::MessEnergies energies;
  double system_volume = 0.0;    // sum of the cell volumes, m^3
                                 // (docs/original-code.md#energies-and-moduli)
  double measured_strain = 0.0;  // strain runs: the applied strain (tan gamma for shear, the
                                 // engineering strain, the twist angle); stress runs: measured
  Eigen::Vector3d box_strain = Eigen::Vector3d::Zero();  // along x, y, z from the face means
                                                         // (analysis/box_strain.hpp)
  Eigen::Matrix3Xd centres;                              // m, 3 x N_p
  Eigen::Matrix3Xd magnetization;                        // A/m, 3 x N_p

  // Solver diagnostics.
  bool converged = false;              // relaxation converged and the final magnetization solve too
  std::string status;                  // the relaxation method's status
  std::int64_t iterations = 0;         // minimiser iterations or leapfrog time steps
  std::int64_t evaluations = 0;        // force evaluations
  std::int64_t krylov_iterations = 0;  // newton: CG iterations (Hessian products); else 0
  // The method that finished the step (finished_by_name): the configured one unless a fallback
  // took over, so that a slow step can be traced to FIRE or the slope-only search.
  std::string finished_by;
  std::int64_t correction_passes = 0;  // seed profile, L-BFGS: correction passes for its forces
  // The multilevel preconditioner of the step's L-BFGS (solvers/preconditioner_cache.hpp):
  // "built" at the step's start, "kept" from an earlier step's start; "none" without one.
  std::string preconditioner = "none";
  // Where the relaxation started (load_step_start.hpp, step_start::): "initial_lattice",
  // "previous", "secant", "neighbour_field", "previous_prediction_rejected".
  std::string start;
  double max_force = 0.0;  // N (minimiser); leapfrog: mean |a| of its last round, scaled
  std::int64_t magnetization_solves = 0;
  std::int64_t unconverged_magnetization_solves = 0;
  std::string magnetization_method;  // of the final solve
  std::int64_t magnetization_iterations = 0;
  double magnetization_residual = 0.0;  // of the final solve, units of Ms
  double wall_time = 0.0;               // s
  // The process's peak resident memory so far (app::peak_resident_memory_bytes) when the step
  // ended, bytes; 0 where not recorded. A run resumed from a checkpoint counts from its resume.
  std::int64_t peak_resident_memory = 0;
};

// The latest converged state at one field (or of the previous step; see above).
struct SlotState {
  KeptPositions positions;         // 0 columns: the initial lattice
  Eigen::Matrix3Xd magnetization;  // 0 columns: no history
};

struct ProtocolState {
  std::size_t next_step = 0;
  std::vector<SlotState> slots;           // one per field for strain/stress runs, else one
  std::vector<KeptPositions> references;  // zero-load result per field (0 columns: unset)
  // Runs with one slot (field loops and series) and solver.field_step_start = "extrapolated":
  // the result of the field step before the one the slot holds (0 columns: none yet), the
  // second point of the field secant (load_step_start.hpp). Runs with a slot per field take it
  // from `references`.
  KeptPositions earlier_field_result;
  // Strain runs with solver.load_step_start = "extrapolated": per field, the start of its latest
  // loaded step, i.e. its result at the load value before the one its slot holds (0 columns:
  // none yet), the earlier point of the next strain step's secant (load_step_start.hpp).
  std::vector<KeptPositions> earlier_load_results;
  // The same runs, between the steps of one load value: how far the last step's result lies
  // from its strain secant, x_k(f) - S_k(f) (secant_miss), and the step's before it, at field
  // f - 1 (earlier_secant_miss); 0 columns: none. Kept only where the next step is field
  // f + 1's at the same load value, whose secant they correct (load_step_start.hpp).
  KeptPositions secant_miss;
  KeptPositions earlier_secant_miss;
  std::vector<StepRecord> records;  // of steps 0 .. next_step - 1
  // Where the multilevel preconditioner the next step may keep was built (solvers/
  // preconditioner_cache.hpp), shared with the runner's cache; null: none (the next step builds
  // one). Checkpoints hold it, so that a resumed run keeps or builds as the uninterrupted one.
  std::shared_ptr<const mess::PreconditionerAnchor> preconditioner_anchor;
  // Where the positions of the fields a step does not work on are parked (kept_positions.hpp);
  // null: all in memory. ProtocolRunner::run_next_step creates it when the runner has a
  // scratch directory (set_scratch_directory) and the state has more than one slot.
  std::shared_ptr<PositionsSpill> spill;
};

class ProtocolRunner {
 public:
  // Builds the lattice and the system (may take a few seconds for the largest systems).
  explicit ProtocolRunner(const mess_config::MessSpec& spec);

  const mess_config::MessSpec& spec() const { return spec_; }
  const std::vector<StepSpec>& steps() const { return steps_; }
  const mess::MessSystem& system() const { return system_; }

  ProtocolState initial_state() const;

  // Whether the run's states keep ProtocolState::earlier_field_result (one slot, and
  // solver.field_step_start = "extrapolated"): after step k it holds step k - 1's result.
  bool keeps_earlier_field_result() const;
  // Whether the run's states keep ProtocolState::earlier_load_results (a strain run with
  // solver.load_step_start = "extrapolated"): after a loaded step at field f it holds that
  // field's result at the load value before.
  bool keeps_earlier_load_results() const;
  // Whether its loaded steps are also offered the starts corrected by the previous fields
  // (solver.load_step_start = "extrapolated"; load_step_start.hpp).
  bool corrects_load_starts() const;

  // The strain secant a loaded step at load value k >= 2 is offered (load_step_start.hpp): from
  // `previous`, the field's result at k - 1 with the step's faces put on, through `earlier`, its
  // result at k - 2 (0 columns: through `zero_load`, the field's zero-load state).
  Eigen::Matrix3Xd strain_secant(const StepSpec& step, const Eigen::Matrix3Xd& previous,
                                 const Eigen::Matrix3Xd& earlier,
                                 const Eigen::Matrix3Xd& zero_load) const;
  // Whether step `index`'s secant miss is kept for the step after it (ProtocolState::
  // secant_miss): that step is the next field's at the same load value k >= 2.
  bool next_step_takes_miss(std::size_t index) const;
  // The steps whose results secant_miss_of reads to recompute step `index`'s secant miss (a
  // rebuilt state, restart/saved_run.hpp): the step itself, its field's at the load value
  // before, at the one before that (k >= 3), and its zero-load step, in this order. Empty where
  // the step keeps no miss for the step after it.
  std::vector<std::size_t> secant_miss_sources(std::size_t index) const;
  // Step `index`'s secant miss, bit for bit as the run kept it, from the results of
  // secant_miss_sources(index), in that order.
  Eigen::Matrix3Xd secant_miss_of(std::size_t index,
                                  const std::vector<Eigen::Matrix3Xd>& results) const;

  // Runs step state.next_step and advances the state. Throws std::logic_error past the end.
  const StepRecord& run_next_step(ProtocolState& state);

  // Runs the remaining steps; after each one calls after_step(state) (checkpoints, progress).
  void run(ProtocolState& state, const std::function<void(const ProtocolState&)>& after_step);

  // Shown the iterations of every relaxation from now on (progress reports; relaxation_observer
  // .hpp). Changes nothing the steps compute.
  void set_relaxation_observer(mess::RelaxationObserver observer) {
    observer_ = std::move(observer);
  }
  // Strain and stress runs park the positions of the fields a step does not work on in an
  // unnamed scratch file in `directory` (kept_positions.hpp), so that their memory does not
  // grow with the number of fields; empty (the default): everything stays in memory. The
  // results are the same either way, bit for bit.
  void set_scratch_directory(std::filesystem::path directory) {
    scratch_directory_ = std::move(directory);
  }

  // Parks every slot's positions and every reference of `state` in state.spill (created on
  // first use) when the runner has a scratch directory and the state more than one slot; else
  // nothing. run_next_step calls it once the system holds the step's start, read_checkpoint
  // after each array it reads.
  void park_kept_positions(ProtocolState& state) const;

  // Every relaxation's evaluations split over the evaluator's MPI processes, each of which runs
  // the same steps on its own runner at the same time (MinimiserOptions::distributed).
  void set_distributed(std::shared_ptr<mess::DistributedEvaluator> evaluator) {
    distributed_ = std::move(evaluator);
  }

 private:
  std::size_t slot_of_field(std::size_t field_index) const;
  const SlotState* start_state(const StepSpec& step, const ProtocolState& state) const;
  // Puts the step's start (start_state: positions and magnetizations; the initial lattice
  // without one) into the system, then parks the kept positions.
  void set_start(const StepSpec& step, ProtocolState& state);
  // The planned step at this field and load value; std::logic_error if there is none.
  const StepSpec& step_at(std::size_t field_index, std::size_t load_index) const;
  // Replaces the start of a loaded step of a strain run (solver.load_step_start) or of a field
  // step (solver.field_step_start) by its prediction (load_step_start.hpp) where that has no
  // higher potential. Call with the step's field and boundary set. Returns how the step starts
  // (step_start::); adds the evaluations it made to `evaluations`.
  // A loaded step's strain secant (strain_secant) is left in `secant` (else 3 x 0).
  std::string predict_start(const StepSpec& step, const ProtocolState& state,
                            std::int64_t& evaluations, Eigen::Matrix3Xd& secant);
  // The corrected secants a loaded step is offered besides `secant` (load_step_start.hpp): none
  // without the previous field's miss; with it S + m_{f-1}, and with the miss before it too
  // S + m_{f-1} + r (m_{f-1} - m_{f-2}).
  std::vector<Eigen::Matrix3Xd> corrected_secants(const StepSpec& step, const ProtocolState& state,
                                                  const Eigen::Matrix3Xd& secant) const;
  // The field secant's start for a field step (load_step_start.hpp), or an empty array where
  // it has no two earlier fields' results.
  Eigen::Matrix3Xd field_secant_candidate(const StepSpec& step, const ProtocolState& state) const;

  // Relaxes the system from its start with the run file's method; fills the record's solver
  // fields (its evaluations: the relaxation's own).
  void relax(const StepSpec& step, StepRecord& record);
  // The run file's solver settings for one relaxation, with the run's caches.
  mess::MinimiserOptions minimiser_options() const;

  mess_config::MessSpec spec_;
  std::vector<StepSpec> steps_;
  mess::MessSystem system_;
  // solver.method = "newton": the multigrid, built at the first step and kept for the others.
  std::shared_ptr<mess::NewtonCache> newton_cache_ = std::make_shared<mess::NewtonCache>();
  // L-BFGS's preconditioner, built at the first step and kept while the free coordinates stay.
  std::shared_ptr<mess::PreconditionerCache> preconditioner_cache_ =
      std::make_shared<mess::PreconditionerCache>();

  mess::RelaxationObserver observer_;
  std::shared_ptr<mess::DistributedEvaluator> distributed_;
  std::filesystem::path scratch_directory_;
};

// Sum of the cell volumes (m^3) at positions x.
double system_volume(const lattice::Lattice& lattice, const Eigen::Matrix3Xd& x);

}  // namespace mresim::mess_protocol
