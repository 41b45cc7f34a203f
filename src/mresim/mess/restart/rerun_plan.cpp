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
#include "mresim/mess/outputs/checkpoint.hpp"
#include "mresim/mess/outputs/mess_outputs.hpp"
#include "mresim/mess/protocols/step_plan.hpp"
#include "mresim/mess/restart/saved_run.hpp"
#include "mresim/mess/run_file/mess_spec.hpp"
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
  }

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
    const std::size_t start = last_restorable(saved, computed, step_);
    progress.set_total(step_ - start + 1);
    ProtocolState state = *state_after(saved, computed, start);
    if (start < step_) {
      std::cerr << fmt::format(
          "mresim: the state before step {} was not kept ([output] node_positions = false); "
          "steps {} to {} are computed again first with the run's settings\n",
          step_, start, step_ - 1);
      ProtocolRunner again(computed_spec_);
      while (state.next_step < step_) {
        again.run_next_step(state);
        progress.advance();
      }
    }
    ProtocolRunner rerunner(rerun_spec_);
    const StepRecord record = rerunner.run_next_step(state);
    progress.advance();
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

 private:
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
