#include "mresim/mess/restart/extend_plan.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <iostream>
#include <utility>

#include "mresim/io/hdf5_reader.hpp"
#include "mresim/io/run_directory.hpp"
#include "mresim/mess/distributed/mpi_job.hpp"
#include "mresim/mess/outputs/checkpoint.hpp"
#include "mresim/mess/outputs/mess_outputs.hpp"
#include "mresim/mess/protocols/step_plan.hpp"
#include "mresim/mess/restart/extension.hpp"
#include "mresim/mess/restart/restart_overrides.hpp"
#include "mresim/mess/restart/saved_run.hpp"
#include "mresim/mess/run_file/mess_spec.hpp"

namespace mresim::mess_protocol {

namespace {

namespace fs = std::filesystem;
namespace mc = mresim::mess_config;

class ExtendPlan final : public app::RunPlan {
 public:
  ExtendPlan(const config::TableReader& computed, const config::TableReader& extended,
             fs::path run_dir, HistoryEntry entry)
      : inner_(app::make_plan(extended)),
        computed_spec_(mc::read_mess_spec(computed, run_type_of(computed))),
        extended_spec_(mc::read_mess_spec(extended, run_type_of(extended))),
        computed_toml_(computed.source_text()),
        extended_toml_(extended.source_text()),
        extended_name_(extended.source_name()),
        run_dir_(std::move(run_dir)),
        entry_(std::move(entry)),
        extension_(plan_extension(plan_steps(computed_spec_), plan_steps(extended_spec_),
                                  overrides_text(entry_.overrides))) {}

  void describe(app::InfoReport& report) const override { inner_->describe(report); }

  void execute(const fs::path& staging_dir, io::Hdf5File& results,
               app::Progress& progress) const override {
    prepare(staging_dir);
    // Under `mpirun -np P` (P > 1) the other processes wait in participate() for the prepared
    // staging directory, then continue from its checkpoint with this process, as `mresim
    // resume` does (the processes share the file system).
    if (mess::mpi_job().size > 1) (void)mess::broadcast_text(staging_dir.string());
    inner_->execute(staging_dir, results, progress);
  }

  // The run type's own plan splits (it refused at construction what cannot).
  [[nodiscard]] bool splits_over_processes() const override {
    return inner_->splits_over_processes();
  }
  [[nodiscard]] bool stops_at_own_safe_points() const override {
    return inner_->stops_at_own_safe_points();
  }

  // The other processes: the extended run from the staging directory that execute() prepared.
  void participate(const fs::path& /*staging_dir*/) const override {
    inner_->participate(mess::broadcast_text({}));
  }

 private:
  static std::string run_type_of(const config::TableReader& root) {
    return app::read_run_settings(root).type;
  }

  // Puts the state to continue from, the kept positions and the history into the staging
  // directory (see extend_plan.hpp).
  void prepare(const fs::path& staging_dir) const {
    SavedRun saved;
    std::vector<HistoryEntry> history;
    {
      ProtocolRunner computed(computed_spec_);
      computed.set_scratch_directory(staging_dir);  // kept_positions.hpp: fields wait on disk
      saved = read_saved_run(run_dir_, computed, computed_toml_);
      const io::Hdf5Reader results(run_dir_ / io::RunDirectory::kMarkerFile);
      history = read_history(results, computed);
    }
    ProtocolRunner extended(extended_spec_);
    extended.set_scratch_directory(staging_dir);
    const std::size_t shared = extension_.shared;
    const std::size_t start = last_restorable(saved, extended, shared, NextStep::as_the_run);
    const std::size_t total = saved.steps.size();
    if (shared < total) {
      std::cerr << fmt::format(
          "mresim: steps {} to {} of the computed run are not steps of the extended protocol; "
          "they are replaced (the old records are kept in /history)\n",
          shared, total - 1);
    }
    if (start < shared) {
      std::cerr << fmt::format(
          "mresim: the state after step {} was not kept ([output] node_positions = false, or "
          "the multilevel preconditioner the next step keeps was built at an earlier step); "
          "steps {} to {} are computed again from step {} (same results)\n",
          shared - 1, start, shared - 1, start);
    }
    if (start > 0) {
      const std::optional<ProtocolState> state = state_after(saved, extended, start);
      write_checkpoint(staging_dir / kCheckpointFile, *state, extended, extended_toml_,
                       extended_name_);
      for (std::size_t k = 0; k < start; ++k) {
        const fs::path kept = step_positions_file(run_dir_, k);
        if (fs::exists(kept)) carry_kept_file(kept, step_positions_file(staging_dir, k));
      }
    }
    HistoryEntry entry = entry_;
    entry.previous_input_toml = computed_toml_;
    entry.added_steps = extension_.added;
    for (std::size_t k = start; k < extended.steps().size(); ++k) {
      const auto index = static_cast<std::int64_t>(k);
      if (std::find(entry.added_steps.begin(), entry.added_steps.end(), index) ==
          entry.added_steps.end()) {
        entry.recomputed_steps.push_back(index);
      }
    }
    for (std::size_t k = start; k < total; ++k) {
      entry.replaced_steps.push_back(static_cast<std::int64_t>(k));
      entry.replaced.push_back(saved.records[k]);
    }
    history.push_back(std::move(entry));
    write_pending_history(staging_dir, history, extended);
  }

  std::unique_ptr<app::RunPlan> inner_;  // the run type's plan of the extended file
  mc::MessSpec computed_spec_;
  mc::MessSpec extended_spec_;
  std::string computed_toml_;
  std::string extended_toml_;
  std::string extended_name_;
  fs::path run_dir_;
  HistoryEntry entry_;
  Extension extension_;
};

}  // namespace

std::unique_ptr<app::RunPlan> make_extend_plan(const config::TableReader& computed,
                                               const config::TableReader& extended,
                                               const std::filesystem::path& run_dir,
                                               HistoryEntry entry) {
  return std::make_unique<ExtendPlan>(computed, extended, run_dir, std::move(entry));
}

}  // namespace mresim::mess_protocol
