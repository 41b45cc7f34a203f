// Run types of the 3D model (Chapter 4): one per registered protocol (protocols/protocol.hpp,
// which calls mess_run_type below). One plan for all: the run file's MessSpec holds the
// protocol the ProtocolRunner follows. Checkpoints go to the staging directory after every
// [output] checkpoint_every steps; `mresim resume` hands the interrupted staging directory back
// to execute(), which continues from its checkpoint. `mresim extend` prepares a staging
// directory the same way (restart/extend_plan.hpp). A finished run keeps its final state
// (final_state.h5) for extend and rerun.

#include "mresim/mess/runs/mess_runs.hpp"

#include <fmt/format.h>

#include <filesystem>
#include <memory>
#include <string>

#include "mresim/app/invalid_results.hpp"
#include "mresim/app/peak_memory.hpp"
#include "mresim/app/run_output.hpp"
#include "mresim/app/run_type.hpp"
#include "mresim/app/stop_signal.hpp"
#include "mresim/mess/distributed/mpi_job.hpp"
#include "mresim/mess/outputs/checkpoint.hpp"
#include "mresim/mess/outputs/mess_outputs.hpp"
#include "mresim/mess/protocols/protocol_runner.hpp"
#include "mresim/mess/protocols/step_plan.hpp"
#include "mresim/mess/restart/run_history.hpp"
#include "mresim/mess/restart/saved_run.hpp"
#include "mresim/mess/run_file/mess_spec.hpp"
#include "mresim/mess/runs/process_split.hpp"
#include "mresim/mess/solvers/amg_preconditioner.hpp"
#include "mresim/mess/solvers/relaxation_observer.hpp"
#include "mresim/pair/runs/pair_outputs.hpp"

namespace mresim::mess_protocol {
namespace {

namespace fs = std::filesystem;
namespace mc = mresim::mess_config;

class MessPlan final : public app::RunPlan {
 public:
  MessPlan(const config::TableReader& root, std::string_view type)
      : spec_(mc::read_mess_spec(root, type)),
        input_toml_(root.source_text()),
        input_name_(root.source_name()) {
    // Refuse what cannot fit before the lattice is allocated or anything is written.
    mc::check_memory(spec_, mc::available_memory());
    // MPI's start forks a helper that would keep results.h5 locked: start it before any file
    // is opened (amg_preconditioner.hpp).
    if (spec_.solver.method == mc::SolverMethod::newton) mess::initialise_petsc();
    // Under `mpirun -np P` (P > 1) every relaxation's evaluations are split over the
    // processes (docs/mpi.md): refuse now, on every process, what cannot be split yet.
    refuse_what_cannot_split(spec_);
  }

  [[nodiscard]] bool splits_over_processes() const override { return true; }
  // A stop request is answered at the next step boundary (execute's loop); after the last
  // step the results are complete and are published.
  [[nodiscard]] bool stops_at_own_safe_points() const override { return true; }

  void describe(app::InfoReport& report) const override { mc::describe_mess(spec_, report); }

  void execute(const fs::path& staging_dir, io::Hdf5File& results,
               app::Progress& progress) const override {
    // Read-time warnings: printed here, not in the constructor, so that `info` (which lists
    // them) and a run file refused later by make_plan print only their own lines.
    pair::runs::print_warnings(spec_.warnings);
    progress.note(setup_line());
    ProtocolRunner runner(spec_);
    // Strain and stress runs keep the fields they are not working on in an unnamed scratch
    // file beside the results (kept_positions.hpp), not in memory.
    runner.set_scratch_directory(staging_dir);
    // Each checkpoint writes only the node arrays that changed (checkpoint.hpp).
    CheckpointWriter checkpoints(staging_dir);
    const bool split = split_over_processes(runner);
    ProtocolState state =
        checkpoints.exists() ? checkpoints.read(runner, input_toml_) : runner.initial_state();
    const std::size_t total = runner.steps().size();
    if (state.next_step > 0) {
      progress.note(fmt::format("mresim: resuming at step {} of {} from the checkpoint",
                                state.next_step, total));
    }
    progress.set_total(total);
    progress.skip(state.next_step);
    const bool leapfrog = spec_.solver.method == mc::SolverMethod::leapfrog;
    progress.set_residual(leapfrog ? "mean |a|" : "max force", leapfrog ? "l_e/t_c^2" : "N");
    runner.set_relaxation_observer([&progress](const mess::RelaxationIteration& it) {
      progress.iteration(it.iteration, it.residual);
    });

    const long every = spec_.output.checkpoint_every;
    while (state.next_step < total) {
      progress.begin_step(step_description(runner.steps()[state.next_step]));
      const StepRecord& record = runner.run_next_step(state);
      // The step line names a fallback that finished the step (it explains a slow step).
      const std::string configured = leapfrog                                          ? "leapfrog"
                                     : spec_.solver.method == mc::SolverMethod::newton ? "newton"
                                                                                       : "lbfgs";
      progress.end_step({record.iterations, record.max_force, record.converged, record.wall_time,
                         record.finished_by == configured ? "" : record.finished_by});
      if (spec_.output.node_positions) {
        write_step_positions(staging_dir, record.step.index, runner.system().positions(),
                             runner.system().lattice().positions);
      }
      if (every > 0 && state.next_step < total &&
          state.next_step % static_cast<std::size_t>(every) == 0) {
        checkpoints.write(state, runner, input_toml_, input_name_);
      }
      // SIGINT/SIGTERM: a step boundary is the safe point; checkpoint (whatever checkpoint_every
      // says) so that `mresim resume` continues from here. Over MPI processes all stop at the
      // same step (participate() asks at the same point).
      // The signal may have reached only some of them: all learn its number.
      const int signal =
          split ? mess::largest_over_processes(app::stop_signal()) : app::stop_signal();
      if (signal != 0 && state.next_step < total) {
        checkpoints.write(state, runner, input_toml_, input_name_);
        throw app::Interrupted(signal, true,
                               fmt::format("after step {} of {}", state.next_step, total));
      }
    }

    const MessResultCheck check = write_mess_results(staging_dir, results, runner, state.records);
    write_peak_memory(results, runner.system().node_count(), progress);
    publish_pending_history(staging_dir, results, runner);          // an extended run's /history
    pair::runs::write_warnings_attribute(results, spec_.warnings);  // /@warnings, as pair runs
    warn_about_intermediate_solves(state.records);
    for (const std::string& fit : check.invalid_fits) {
      app::warn("invalid modulus fit, not a result: " + fit +
                " (marked in /analysis/valid and modulus.csv)");
    }
    // The state after the last step stays with the results, for `mresim extend` and `rerun`
    // (restart/saved_run.hpp); the checkpoint is not needed any more.
    if (spec_.output.keep_final_state) {
      write_checkpoint(staging_dir / kFinalStateFile, state, runner, input_toml_, input_name_);
    }
    checkpoints.remove();
    // Non-finite or unconverged steps: the results stay, marked; `mresim run` exits with 4.
    const std::string invalid = check.message();
    if (!invalid.empty()) throw app::InvalidResults(invalid);
  }

  // The other processes of `mpirun -np P`: execute()'s computation, collectively with it,
  // writing nothing; a resumed run starts from the checkpoint in rank 0's staging directory,
  // as execute() does.
  void participate(const fs::path& staging_dir) const override {
    ProtocolRunner runner(spec_);
    (void)split_over_processes(runner);
    // As execute() does; a process without the staging directory uses the temporary directory
    // (TMPDIR).
    runner.set_scratch_directory(staging_dir.empty() ? fs::temp_directory_path() : staging_dir);
    const fs::path checkpoint = staging_dir.empty() ? fs::path() : staging_dir / kCheckpointFile;
    ProtocolState state = !checkpoint.empty() && fs::exists(checkpoint)
                              ? read_checkpoint(checkpoint, runner, input_toml_)
                              : runner.initial_state();
    const std::size_t total = runner.steps().size();
    while (state.next_step < total) {
      (void)runner.run_next_step(state);
      if (mess::largest_over_processes(app::stop_signal()) != 0 && state.next_step < total) {
        return;
      }
    }
  }

 private:
  // The process's peak resident memory so far (the relaxations are done), in results.h5 and
  // in the log, absolute and per lattice node.
  static void write_peak_memory(io::Hdf5File& results, std::int64_t nodes,
                                app::Progress& progress) {
    const std::int64_t peak = app::peak_resident_memory_bytes();
    if (peak <= 0) return;
    const double per_node = static_cast<double>(peak) / static_cast<double>(nodes);
    results.write_int_attribute("/", "peak_resident_memory_bytes", peak);
    results.write_number_attribute("/", "peak_resident_memory_bytes_per_node", per_node);
    progress.note(fmt::format("mresim: peak resident memory {:.1f} MiB ({:.0f} bytes per node)",
                              static_cast<double>(peak) / (1 << 20), per_node));
  }

  // "mresim: lattice 42 x 42 x 83 nodes (146412 nodes, 5 particles), 21 steps, solver lbfgs,
  // memory estimate 230.1 MiB (available 100.0 GiB, MemAvailable)".
  std::string setup_line() const {
    const auto& g = spec_.geometry;
    const mc::AvailableMemory available = mc::available_memory();
    const auto gib = [](std::int64_t bytes) {
      return bytes >= (std::int64_t{1} << 30)
                 ? fmt::format("{:.1f} GiB", static_cast<double>(bytes) / (1 << 30))
                 : fmt::format("{:.1f} MiB", static_cast<double>(bytes) / (1 << 20));
    };
    const char* method = mc::solver_method_name(spec_.solver.method);
    std::string line = fmt::format(
        "mresim: lattice {} x {} x {} nodes ({} nodes, {} particles), {} steps, solver {}, "
        "memory estimate {}",
        g.shape.nx(), g.shape.ny(), g.shape.nz(), g.node_count(), g.particle_count(),
        plan_steps(spec_).size(), method, gib(mc::estimated_memory_bytes(spec_)));
    if (available.bytes)
      line += fmt::format(" (available {}, {})", gib(*available.bytes), available.source);
    return line;
  }

  // "B 0.100 T" (along the run's field direction), with ", strain 0.01" for loaded protocols.
  std::string step_description(const StepSpec& step) const {
    std::string what = fmt::format("B {:.4g} T", step.field.dot(field_direction(spec_)));
    if (spec_.load_step_count() > 1) {
      const std::string unit = load_unit(spec_);
      what += fmt::format(", load {:.4g}{}", step.load_value, unit == "1" ? "" : " " + unit);
    }
    return what;
  }

  // A magnetization solve that missed its tolerance during a step whose final solve converged
  // leaves a valid step; it is reported, not an error.
  static void warn_about_intermediate_solves(const std::vector<StepRecord>& records) {
    std::size_t magnetization = 0;
    for (const StepRecord& r : records) {
      if (r.unconverged_magnetization_solves > 0) ++magnetization;
    }
    if (magnetization > 0) {
      app::warn(
          fmt::format("in {} of {} steps some magnetization solve missed its tolerance "
                      "(see /steps/solver/unconverged_magnetization_solves)",
                      magnetization, records.size()));
    }
  }

  mc::MessSpec spec_;
  std::string input_toml_;
  std::string input_name_;
};

}  // namespace
}  // namespace mresim::mess_protocol

namespace mresim::mess_runs {

app::RunType mess_run_type(const std::string& name, const std::string& summary) {
  return {name, summary, [name](const config::TableReader& root) {
            return std::make_unique<mess_protocol::MessPlan>(root, name);
          }};
}

}  // namespace mresim::mess_runs
