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
#include <iostream>
#include <memory>
#include <string>

#include "mresim/app/invalid_results.hpp"
#include "mresim/app/run_type.hpp"
#include "mresim/app/stop_signal.hpp"
#include "mresim/mess/outputs/checkpoint.hpp"
#include "mresim/mess/outputs/mess_outputs.hpp"
#include "mresim/mess/protocols/protocol_runner.hpp"
#include "mresim/mess/restart/run_history.hpp"
#include "mresim/mess/restart/saved_run.hpp"
#include "mresim/mess/run_file/mess_spec.hpp"
#include "mresim/mess/solvers/amg_preconditioner.hpp"
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
  }

  void describe(app::InfoReport& report) const override { mc::describe_mess(spec_, report); }

  void execute(const fs::path& staging_dir, io::Hdf5File& results,
               app::Progress& progress) const override {
    // Read-time warnings: printed here, not in the constructor, so that `info` (which lists
    // them) and a run file refused later by make_plan print only their own lines.
    pair::runs::print_warnings(spec_.warnings);
    ProtocolRunner runner(spec_);
    const fs::path checkpoint = staging_dir / kCheckpointFile;
    ProtocolState state = fs::exists(checkpoint) ? read_checkpoint(checkpoint, runner, input_toml_)
                                                 : runner.initial_state();
    const std::size_t total = runner.steps().size();
    if (state.next_step > 0) {
      std::cerr << fmt::format("mresim: resuming at step {} of {} from the checkpoint\n",
                               state.next_step, total);
    }
    progress.set_total(total);
    progress.advance(state.next_step);

    const long every = spec_.output.checkpoint_every;
    runner.run(state, [&](const ProtocolState& s) {
      if (spec_.output.node_positions) {
        write_step_positions(staging_dir, s.records.back().step.index, runner.system().positions(),
                             runner.system().lattice().positions);
      }
      if (every > 0 && s.next_step < total && s.next_step % static_cast<std::size_t>(every) == 0) {
        write_checkpoint(checkpoint, s, runner, input_toml_, input_name_);
      }
      progress.advance();
      // SIGINT/SIGTERM: a step boundary is the safe point; checkpoint (whatever checkpoint_every
      // says) so that `mresim resume` continues from here.
      if (app::stop_requested() && s.next_step < total) {
        write_checkpoint(checkpoint, s, runner, input_toml_, input_name_);
        throw app::Interrupted(app::stop_signal(), true,
                               fmt::format("after step {} of {}", s.next_step, total));
      }
    });

    const MessResultCheck check = write_mess_results(staging_dir, results, runner, state.records);
    publish_pending_history(staging_dir, results, runner);          // an extended run's /history
    pair::runs::write_warnings_attribute(results, spec_.warnings);  // /@warnings, as pair runs
    warn_about_intermediate_solves(state.records);
    for (const std::string& fit : check.invalid_fits) {
      std::cerr << "mresim: warning: invalid modulus fit, not a result: " << fit
                << " (marked in /analysis/valid and modulus.csv)\n";
    }
    // The state after the last step stays with the results, for `mresim extend` and `rerun`
    // (restart/saved_run.hpp); the checkpoint is not needed any more.
    if (spec_.output.keep_final_state) {
      write_checkpoint(staging_dir / kFinalStateFile, state, runner, input_toml_, input_name_);
    }
    std::error_code ec;
    fs::remove(checkpoint, ec);
    // Non-finite or unconverged steps: the results stay, marked; `mresim run` exits with 4.
    const std::string invalid = check.message();
    if (!invalid.empty()) throw app::InvalidResults(invalid);
  }

 private:
  // A magnetization solve that missed its tolerance during a step whose final solve converged
  // leaves a valid step; it is reported, not an error.
  static void warn_about_intermediate_solves(const std::vector<StepRecord>& records) {
    std::size_t magnetization = 0;
    for (const StepRecord& r : records) {
      if (r.unconverged_magnetization_solves > 0) ++magnetization;
    }
    if (magnetization > 0) {
      std::cerr << fmt::format(
          "mresim: warning: in {} of {} steps some magnetization solve missed its tolerance "
          "(see /steps/solver/unconverged_magnetization_solves)\n",
          magnetization, records.size());
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
