#include "mresim/mess/restart/rerun_plan.hpp"

#include <fmt/format.h>

#include <cmath>
#include <cstdio>
#include <iostream>
#include <utility>

#include "mresim/app/invalid_results.hpp"
#include "mresim/config/config_error.hpp"
#include "mresim/io/hdf5_reader.hpp"
#include "mresim/io/run_directory.hpp"
#include "mresim/mess/distributed/mpi_job.hpp"
#include "mresim/mess/outputs/checkpoint.hpp"
#include "mresim/mess/outputs/mess_outputs.hpp"
#include "mresim/mess/protocols/step_plan.hpp"
#include "mresim/mess/restart/saved_run.hpp"
#include "mresim/mess/run_file/mess_spec.hpp"
#include "mresim/mess/runs/process_split.hpp"
#include "mresim/mess/solvers/amg_preconditioner.hpp"
#include "mresim/pair/runs/pair_outputs.hpp"

namespace mresim::mess_protocol {

namespace {

namespace fs = std::filesystem;
namespace mc = mresim::mess_config;

std::string run_type_of(const config::TableReader& root) {
  return app::read_run_settings(root).type;
}

// One line per diagnostic, old -> new, so the effect of the settings is seen at once.
void print_comparison(std::size_t step, const StepRecord& before, const StepRecord& after) {
  const double total_before = before.energies.total();
  const double total_after = after.energies.total();
  const double change = std::abs(total_after - total_before) /
                        std::max(std::abs(total_before), std::abs(total_after));
  std::printf(
      "mresim: step %zu rerun: status %s -> %s, converged %s -> %s, iterations %lld -> %lld, "
      "max force %.4g -> %.4g N, total energy %.12g -> %.12g J (relative change %.3g)\n",
      step, before.status.c_str(), after.status.c_str(), before.converged ? "yes" : "no",
      after.converged ? "yes" : "no", static_cast<long long>(before.iterations),
      static_cast<long long>(after.iterations), before.max_force, after.max_force, total_before,
      total_after, std::isfinite(change) ? change : 0.0);
  std::fflush(stdout);
}

class RerunPlan final : public app::RunPlan {
 public:
  RerunPlan(const config::TableReader& computed, const config::TableReader& rerun, fs::path run_dir,
            std::size_t step, HistoryEntry entry)
      : computed_spec_(mc::read_mess_spec(computed, run_type_of(computed))),
        rerun_spec_(mc::read_mess_spec(rerun, run_type_of(rerun))),
        computed_toml_(computed.source_text()),
        computed_name_(computed.source_name()),
        run_dir_(std::move(run_dir)),
        step_(step),
        entry_(std::move(entry)) {
    app::make_plan(rerun);  // the unknown-key check of the overridden file
    const std::size_t total = plan_steps(computed_spec_).size();
    if (step_ >= total) {
      throw config::ConfigError(
          fmt::format("--step {}: the run has {} steps (0 to {})", step_, total, total - 1));
    }
    // MPI's start forks a helper that would keep results.h5 locked (mess_runs.cpp).
    if (rerun_spec_.solver.method == mc::SolverMethod::newton ||
        computed_spec_.solver.method == mc::SolverMethod::newton) {
      mess::initialise_petsc();
    }
    // Under `mpirun -np P` (P > 1) both relaxations split over the processes: the rerun's
    // (make_plan above refused what it cannot split) and, where the state before step K was not
    // kept, the run's own for the steps before it.
    if (mess::mpi_job().size > 1) refuse_recomputation_that_cannot_split();
  }

  [[nodiscard]] bool splits_over_processes() const override { return true; }

  void describe(app::InfoReport& report) const override { mc::describe_mess(rerun_spec_, report); }

  void execute(const fs::path& staging_dir, io::Hdf5File& results,
               app::Progress& progress) const override {
    pair::runs::print_warnings(computed_spec_.warnings);
    ProtocolRunner computed(computed_spec_);
    // The saved run's fields wait in a scratch file while one step is relaxed again, as in the
    // run itself (kept_positions.hpp).
    computed.set_scratch_directory(staging_dir);
    SavedRun saved = read_saved_run(run_dir_, computed, computed_toml_);
    std::vector<HistoryEntry> history;
    {
      const io::Hdf5Reader old_results(run_dir_ / io::RunDirectory::kMarkerFile);
      history = read_history(old_results, computed);
    }
    ProtocolRunner rerunner(rerun_spec_);
    const StepRecord record = relax_step(saved, computed, rerunner, &progress);
    print_comparison(step_, saved.records[step_], record);

    HistoryEntry entry = entry_;
    entry.previous_input_toml = computed_toml_;
    entry.recomputed_steps = {static_cast<std::int64_t>(step_)};
    entry.replaced_steps = {static_cast<std::int64_t>(step_)};
    entry.replaced = {saved.records[step_]};
    history.push_back(std::move(entry));

    // The new result replaces the old one everywhere the run keeps it.
    saved.records[step_] = record;
    const bool positions_kept = saved.positions.contains(step_);
    if (positions_kept) {
      saved.positions.insert_or_assign(
          step_, SavedPositions(KeptPositions(rerunner.system().positions())));
    }
    for (std::size_t k = 0; k < saved.steps.size(); ++k) {
      const fs::path kept = step_positions_file(run_dir_, k);
      if (k != step_ && fs::exists(kept))
        carry_kept_file(kept, step_positions_file(staging_dir, k));
    }
    if (computed_spec_.output.node_positions) {
      write_step_positions(staging_dir, step_, rerunner.system().positions(),
                           rerunner.system().lattice().positions);
    }
    if (saved.has_final_state) {
      write_checkpoint(staging_dir / kFinalStateFile,
                       *state_after(saved, computed, saved.steps.size()), computed, computed_toml_,
                       computed_name_);
    }
    const MessResultCheck check = write_mess_results(staging_dir, results, computed, saved.records);
    pair::runs::write_warnings_attribute(results, computed_spec_.warnings);
    write_history(results, history, computed);
    const std::string invalid = check.message();
    if (!invalid.empty()) throw app::InvalidResults(invalid);
  }

  // The other processes of `mpirun -np P`: execute()'s relaxations, collectively with it,
  // writing nothing (the saved run is read from the run directory, which the processes share).
  void participate(const fs::path& /*staging_dir*/) const override {
    ProtocolRunner computed(computed_spec_);
    computed.set_scratch_directory(fs::temp_directory_path());  // as MessPlan::participate
    SavedRun saved = read_saved_run(run_dir_, computed, computed_toml_);
    ProtocolRunner rerunner(rerun_spec_);
    (void)relax_step(saved, computed, rerunner, nullptr);
  }

 private:
  // Relaxes step K again into `rerunner`, from the state before it: restored from `saved`, or,
  // where it was not kept, computed again from the latest kept one with the run's own
  // settings. `progress`: rank 0's (or a single process's), null on the other processes.
  StepRecord relax_step(const SavedRun& saved, const ProtocolRunner& computed,
                        ProtocolRunner& rerunner, app::Progress* progress) const {
    const std::size_t start = last_restorable(saved, computed, step_, NextStep::afresh);
    if (progress != nullptr) progress->set_total(step_ - start + 1);
    ProtocolState state = *state_after(saved, computed, start);
    if (start < step_) {
      if (progress != nullptr) {
        std::cerr << fmt::format(
            "mresim: the state before step {} was not kept ([output] node_positions = false, "
            "or a multilevel preconditioner kept from an earlier step is needed); steps {} to {} "
            "are computed again first with the run's settings\n",
            step_, start, step_ - 1);
      }
      ProtocolRunner again(computed_spec_);
      (void)split_over_processes(again);
      while (state.next_step < step_) {
        again.run_next_step(state);
        if (progress != nullptr) progress->advance();
      }
    }
    (void)split_over_processes(rerunner);
    StepRecord record = rerunner.run_next_step(state);
    if (progress != nullptr) progress->advance();
    return record;
  }

  // Under mpirun: the steps before K are computed again only where a state before K was not
  // kept; refuse that (before anything is written) when the run's own solver cannot split. The
  // energy terms are the rerun's, which make_plan checked. Every step's positions before K kept
  // is enough for the state before K (saved_run.hpp).
  void refuse_recomputation_that_cannot_split() const {
    const mc::SolverMethod method = computed_spec_.solver.method;
    if (method_splits_over_processes(method)) return;
    for (std::size_t k = 0; k < step_; ++k) {
      if (!fs::exists(step_positions_file(run_dir_, k))) {
        throw config::ConfigError(fmt::format(
            "--step {}: the state before it was not kept ([output] node_positions = false), so "
            "steps before it would be computed again with the run's solver.method = \"{}\", "
            "which cannot split over MPI processes (docs/mpi.md); run this rerun without mpirun",
            step_, mc::solver_method_name(method)));
      }
    }
  }

  mc::MessSpec computed_spec_;
  mc::MessSpec rerun_spec_;
  std::string computed_toml_;
  std::string computed_name_;
  fs::path run_dir_;
  std::size_t step_;
  HistoryEntry entry_;
};

}  // namespace

std::unique_ptr<app::RunPlan> make_rerun_plan(const config::TableReader& computed,
                                              const config::TableReader& rerun,
                                              const std::filesystem::path& run_dir,
                                              std::size_t step, HistoryEntry entry) {
  return std::make_unique<RerunPlan>(computed, rerun, run_dir, step, std::move(entry));
}

}  // namespace mresim::mess_protocol
