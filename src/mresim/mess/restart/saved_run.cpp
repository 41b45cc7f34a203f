#include "mresim/mess/restart/saved_run.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <stdexcept>

#include "mresim/io/hdf5_reader.hpp"
#include "mresim/mess/outputs/checkpoint.hpp"
#include "mresim/mess/outputs/mess_outputs.hpp"
#include "mresim/mess/outputs/step_records_io.hpp"

namespace mresim::mess_protocol {

namespace fs = std::filesystem;

namespace {

// The slot a step's result goes to in a state with `slots` slots (protocol_runner.cpp).
std::size_t slot_of(const StepSpec& step, std::size_t slots) {
  return slots > 1 ? step.field_index : 0;
}

// The final state's slots, references and earlier load results hold the results of these steps:
// their arrays move over as they are (parked or in memory).
void take_final_state(ProtocolState& final, const std::vector<StepSpec>& steps,
                      std::map<std::size_t, SavedPositions>& positions) {
  std::vector<std::optional<std::size_t>> last_in_slot(final.slots.size());
  std::vector<std::optional<std::size_t>> reference_step(final.references.size());
  std::vector<std::optional<std::size_t>> earlier_load_step(final.earlier_load_results.size());
  for (std::size_t k = 0; k < final.next_step; ++k) {
    if (steps[k].load_index > 0 && !final.earlier_load_results.empty()) {
      earlier_load_step.at(steps[k].field_index) =
          last_in_slot.at(slot_of(steps[k], final.slots.size()));
    }
    last_in_slot.at(slot_of(steps[k], final.slots.size())) = k;
    if (steps[k].load_index == 0 && !final.references.empty()) {
      reference_step.at(steps[k].field_index) = k;
    }
  }
  for (std::size_t s = 0; s < last_in_slot.size(); ++s) {
    if (last_in_slot[s] && final.slots[s].positions.cols() > 0) {
      positions.insert_or_assign(*last_in_slot[s],
                                 SavedPositions(std::move(final.slots[s].positions)));
    }
  }
  for (std::size_t f = 0; f < reference_step.size(); ++f) {
    if (reference_step[f] && final.references[f].cols() > 0) {
      positions.insert_or_assign(*reference_step[f],
                                 SavedPositions(std::move(final.references[f])));
    }
  }
  for (std::size_t f = 0; f < earlier_load_step.size(); ++f) {
    if (earlier_load_step[f] && final.earlier_load_results[f].cols() > 0) {
      positions.insert_or_assign(*earlier_load_step[f],
                                 SavedPositions(std::move(final.earlier_load_results[f])));
    }
  }
  // One slot: the result of the step before the last (ProtocolState::earlier_field_result).
  if (final.next_step >= 2 && final.earlier_field_result.cols() > 0) {
    positions.insert_or_assign(final.next_step - 2,
                               SavedPositions(std::move(final.earlier_field_result)));
  }
}

}  // namespace

SavedRun read_saved_run(const fs::path& dir, const ProtocolRunner& runner,
                        const std::string& input_toml) {
  SavedRun saved;
  saved.steps = runner.steps();
  const fs::path final_state = dir / kFinalStateFile;
  std::error_code ec;
  if (fs::exists(final_state, ec)) {
    // The exact records (results.h5 writes non-finite numbers as NaN) and the final positions.
    ProtocolState final = read_checkpoint(final_state, runner, input_toml);
    if (final.next_step != saved.steps.size()) {
      throw std::runtime_error(fmt::format("{} holds the state after {} of {} steps",
                                           final_state.string(), final.next_step,
                                           saved.steps.size()));
    }
    take_final_state(final, saved.steps, saved.positions);
    saved.final_anchor = std::move(final.preconditioner_anchor);
    saved.records = final.records;
    saved.has_final_state = true;
  } else {
    const io::Hdf5Reader results(dir / "results.h5");
    saved.records =
        read_step_records(results, "/steps", saved.steps, runner.system().particle_count(),
                          runner.system().energy_labels());
    if (saved.records.size() != saved.steps.size()) {
      throw std::runtime_error(fmt::format("{} holds {} of the run's {} steps",
                                           (dir / "results.h5").string(), saved.records.size(),
                                           saved.steps.size()));
    }
  }
  for (std::size_t k = 0; k < saved.steps.size(); ++k) {
    const fs::path file = step_positions_file(dir, k);
    if (saved.positions.contains(k) || !fs::exists(file, ec)) continue;
    saved.positions.emplace(k, SavedPositions(file));
  }
  return saved;
}

Eigen::Matrix3Xd SavedPositions::load() const {
  if (file_.empty()) return kept_.load();
  const io::Hdf5Reader in(file_);
  return read_columns(in, "/positions");
}

namespace {

// The steps whose results the state after `count` steps holds: the latest step of each slot,
// the zero-load step of each field and, where the runner keeps one, the step before the slot's
// latest (nullopt: untouched, the initial lattice; none).
struct StateSources {
  std::vector<std::optional<std::size_t>> slots;
  std::vector<std::optional<std::size_t>> references;
  std::optional<std::size_t> earlier_field_result;
  std::vector<std::optional<std::size_t>> earlier_load_results;
  // The steps whose secant misses the state holds (ProtocolState::secant_miss,
  // earlier_secant_miss).
  std::optional<std::size_t> secant_miss;
  std::optional<std::size_t> earlier_secant_miss;
};

StateSources sources_after(const SavedRun& saved, const ProtocolRunner& runner,
                           const ProtocolState& initial, std::size_t count) {
  StateSources sources{std::vector<std::optional<std::size_t>>(initial.slots.size()),
                       std::vector<std::optional<std::size_t>>(initial.references.size()),
                       std::nullopt,
                       std::vector<std::optional<std::size_t>>(initial.earlier_load_results.size()),
                       std::nullopt,
                       std::nullopt};
  if (runner.keeps_earlier_field_result() && count >= 2) sources.earlier_field_result = count - 2;
  for (std::size_t k = 0; k < count; ++k) {
    const StepSpec& step = saved.steps[k];
    // A loaded step keeps its start, the slot's result before it (ProtocolRunner).
    if (step.load_index > 0 && !initial.earlier_load_results.empty()) {
      sources.earlier_load_results.at(step.field_index) =
          sources.slots.at(slot_of(step, initial.slots.size()));
    }
    sources.slots.at(slot_of(step, initial.slots.size())) = k;
    if (step.load_index == 0 && !initial.references.empty()) {
      sources.references.at(step.field_index) = k;
    }
  }
  // A step keeps its miss only for the step after it (ProtocolRunner::next_step_takes_miss).
  if (count >= 1 && runner.next_step_takes_miss(count - 1)) {
    sources.secant_miss = count - 1;
    if (count >= 2 && runner.next_step_takes_miss(count - 2)) {
      sources.earlier_secant_miss = count - 2;
    }
  }
  return sources;
}

bool kept(const SavedRun& saved, const std::vector<std::optional<std::size_t>>& steps) {
  return std::ranges::all_of(steps,
                             [&](const auto& k) { return !k || saved.positions.contains(*k); });
}

// The results a secant miss is recomputed from (ProtocolRunner::secant_miss_sources).
std::vector<std::optional<std::size_t>> miss_sources(const ProtocolRunner& runner,
                                                     const std::optional<std::size_t>& step) {
  std::vector<std::optional<std::size_t>> sources;
  if (!step) return sources;
  for (const std::size_t k : runner.secant_miss_sources(*step)) sources.emplace_back(k);
  return sources;
}

bool restorable(const SavedRun& saved, const ProtocolRunner& runner, const ProtocolState& initial,
                std::size_t count) {
  if (count > saved.records.size() || count > saved.steps.size()) return false;
  const StateSources sources = sources_after(saved, runner, initial, count);
  return kept(saved, sources.slots) && kept(saved, sources.references) &&
         kept(saved, {sources.earlier_field_result}) && kept(saved, sources.earlier_load_results) &&
         kept(saved, miss_sources(runner, sources.secant_miss)) &&
         kept(saved, miss_sources(runner, sources.earlier_secant_miss));
}

// Step `step`'s secant miss recomputed from the saved results; none without a step.
KeptPositions recomputed_miss(const SavedRun& saved, const ProtocolRunner& runner,
                              const std::optional<std::size_t>& step) {
  if (!step) return {};
  std::vector<Eigen::Matrix3Xd> results;
  for (const std::size_t k : runner.secant_miss_sources(*step)) {
    results.push_back(saved.positions.at(k).load());
  }
  return runner.secant_miss_of(*step, results);
}

// Whether a run continued from the state after `count` steps builds or keeps the multilevel
// preconditioner as the saved run did (preconditioner_cache.hpp): where the step after it may
// keep one built before, the anchor it was built at must be known. It is for the final state
// (final_state.h5 holds it) and where no anchor was in effect; a next step that is the saved
// run's own and built its preconditioner at its start needs none either.
bool anchor_known(const SavedRun& saved, const ProtocolRunner& runner, std::size_t count,
                  bool next_step_is_saved) {
  if (next_step_is_saved && count < saved.records.size()) {
    return saved.records[count].preconditioner != "kept";
  }
  if (count == 0 || runner.spec().solver.preconditioner_reuse <= 0.0) return true;
  if (count == saved.steps.size() && saved.has_final_state) return true;
  const std::string& before = saved.records[count - 1].preconditioner;
  return before != "built" && before != "kept";
}

}  // namespace

std::optional<ProtocolState> state_after(const SavedRun& saved, const ProtocolRunner& runner,
                                         std::size_t count) {
  ProtocolState state = runner.initial_state();
  if (count > runner.steps().size() || !restorable(saved, runner, state, count)) {
    return std::nullopt;
  }
  const StateSources sources = sources_after(saved, runner, state, count);
  for (std::size_t s = 0; s < state.slots.size(); ++s) {
    if (!sources.slots[s]) continue;
    state.slots[s].positions = saved.positions.at(*sources.slots[s]).load();
    state.slots[s].magnetization = saved.records[*sources.slots[s]].magnetization;
    runner.park_kept_positions(state);  // one array in memory at a time where the runner parks
  }
  for (std::size_t f = 0; f < state.references.size(); ++f) {
    if (!sources.references[f]) continue;
    state.references[f] = saved.positions.at(*sources.references[f]).load();
    runner.park_kept_positions(state);
  }
  for (std::size_t f = 0; f < state.earlier_load_results.size(); ++f) {
    if (!sources.earlier_load_results[f]) continue;
    state.earlier_load_results[f] = saved.positions.at(*sources.earlier_load_results[f]).load();
    runner.park_kept_positions(state);
  }
  if (sources.earlier_field_result) {
    state.earlier_field_result = saved.positions.at(*sources.earlier_field_result).load();
  }
  state.secant_miss = recomputed_miss(saved, runner, sources.secant_miss);
  state.earlier_secant_miss = recomputed_miss(saved, runner, sources.earlier_secant_miss);
  runner.park_kept_positions(state);
  if (count == saved.steps.size()) state.preconditioner_anchor = saved.final_anchor;
  state.records.assign(saved.records.begin(),
                       saved.records.begin() + static_cast<std::ptrdiff_t>(count));
  state.next_step = count;
  return state;
}

std::size_t last_restorable(const SavedRun& saved, const ProtocolRunner& runner, std::size_t count,
                            NextStep next) {
  const ProtocolState initial = runner.initial_state();
  const std::size_t last = std::min(count, runner.steps().size());
  for (std::size_t k = last; k > 0; --k) {
    if (!restorable(saved, runner, initial, k)) continue;
    if (k == last && next == NextStep::afresh) return k;
    if (anchor_known(saved, runner, k, k < last)) return k;
  }
  return 0;
}

void carry_kept_file(const fs::path& from, const fs::path& to) {
  fs::create_directories(to.parent_path());
  std::error_code ec;
  fs::create_hard_link(from, to, ec);
  if (ec) fs::copy_file(from, to, fs::copy_options::overwrite_existing);
}

}  // namespace mresim::mess_protocol
