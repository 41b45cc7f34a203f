#include "mresim/mess/outputs/checkpoint.hpp"

#include <fmt/format.h>

#include <bit>
#include <cstdint>
#include <memory>
#include <stdexcept>

#include "mresim/io/hdf5_file.hpp"
#include "mresim/io/hdf5_reader.hpp"
#include "mresim/mess/outputs/step_records_io.hpp"
#include "mresim/mess/protocols/step_plan.hpp"

namespace mresim::mess_protocol {

namespace fs = std::filesystem;

namespace {

// 2: the records have box_strain (a version-1 checkpoint cannot be resumed).
constexpr std::int64_t kFormatVersion = 2;

// ProtocolState::earlier_field_result, where the state holds one.
constexpr const char* kEarlierFieldResult = "/earlier_field_result";
// ProtocolState::preconditioner_anchor, where the state holds one: its positions (single
// precision values, stored exactly as doubles) with the key as an attribute.
constexpr const char* kPreconditionerAnchor = "/preconditioner_anchor";

void write_optional(io::Hdf5File& file, const std::string& path, const Eigen::Matrix3Xd& m,
                    std::string_view unit) {
  if (m.cols() > 0) write_columns(file, path, m, unit);
}

Eigen::Matrix3Xd read_optional(const io::Hdf5Reader& file, const std::string& path,
                               Eigen::Index expected_columns) {
  if (!file.exists(path)) return {};
  Eigen::Matrix3Xd m = read_columns(file, path);
  if (m.cols() != expected_columns) {
    throw std::runtime_error(
        fmt::format("checkpoint: {} has {} rows, expected {}", path, m.cols(), expected_columns));
  }
  return m;
}

}  // namespace

void write_checkpoint(const fs::path& file, const ProtocolState& state,
                      const ProtocolRunner& runner, std::string_view input_toml,
                      std::string_view input_name) {
  const fs::path temporary = fs::path(file.string() + ".tmp");
  {
    io::Hdf5File out(temporary);
    out.write_int_attribute("/", "format_version", kFormatVersion);
    out.write_string_attribute("/", "input_toml", input_toml);
    out.write_string_attribute("/", "input_file", input_name);
    out.write_int_attribute("/", "next_step", static_cast<std::int64_t>(state.next_step));
    out.write_int_attribute("/", "slots", static_cast<std::int64_t>(state.slots.size()));
    out.write_int_attribute("/", "references", static_cast<std::int64_t>(state.references.size()));
    for (std::size_t i = 0; i < state.slots.size(); ++i) {
      write_optional(out, fmt::format("/slots/{}/positions", i), state.slots[i].positions.load(),
                     "m");
      write_optional(out, fmt::format("/slots/{}/magnetization", i), state.slots[i].magnetization,
                     "A/m");
    }
    for (std::size_t i = 0; i < state.references.size(); ++i) {
      write_optional(out, fmt::format("/references/{}", i), state.references[i].load(), "m");
    }
    if (state.earlier_field_result.cols() > 0) {
      write_optional(out, kEarlierFieldResult, state.earlier_field_result.load(), "m");
    }
    if (state.preconditioner_anchor != nullptr) {
      write_columns(out, kPreconditionerAnchor,
                    state.preconditioner_anchor->positions.cast<double>(), "m");
      out.write_int_attribute(kPreconditionerAnchor, "key",
                              std::bit_cast<std::int64_t>(state.preconditioner_anchor->key));
    }
    if (!state.records.empty()) {
      write_step_records(out, "/records", state.records, runner.system().particle_count(),
                         load_unit(runner.spec()), *runner.system().energy_labels());
    }
    out.close();
  }
  fs::rename(temporary, file);
}

ProtocolState read_checkpoint(const fs::path& file, const ProtocolRunner& runner,
                              std::string_view input_toml) {
  const io::Hdf5Reader in(file);
  if (in.int_attribute("/", "format_version") != kFormatVersion) {
    throw std::runtime_error("checkpoint " + file.string() + ": unknown format version");
  }
  if (in.string_attribute("/", "input_toml") != input_toml) {
    throw std::runtime_error("checkpoint " + file.string() +
                             " was written for a different run file");
  }
  ProtocolState state = runner.initial_state();
  const auto next = static_cast<std::size_t>(in.int_attribute("/", "next_step"));
  if (next > runner.steps().size() ||
      static_cast<std::size_t>(in.int_attribute("/", "slots")) != state.slots.size() ||
      static_cast<std::size_t>(in.int_attribute("/", "references")) != state.references.size()) {
    throw std::runtime_error("checkpoint " + file.string() + " does not match the run's steps");
  }
  const Eigen::Index nodes = runner.system().node_count();
  const auto particles = static_cast<Eigen::Index>(runner.system().particle_count());
  for (std::size_t i = 0; i < state.slots.size(); ++i) {
    state.slots[i].positions = read_optional(in, fmt::format("/slots/{}/positions", i), nodes);
    state.slots[i].magnetization =
        read_optional(in, fmt::format("/slots/{}/magnetization", i), particles);
    runner.park_kept_positions(state);  // one field's array in memory at a time, at most
  }
  for (std::size_t i = 0; i < state.references.size(); ++i) {
    state.references[i] = read_optional(in, fmt::format("/references/{}", i), nodes);
    runner.park_kept_positions(state);
  }
  // Absent in checkpoints of runs without the field secant (and in those written before it).
  state.earlier_field_result = read_optional(in, kEarlierFieldResult, nodes);
  // Absent in checkpoints of runs that build the preconditioner at every step (and in those
  // written before it was kept).
  const Eigen::Matrix3Xd anchor = read_optional(in, kPreconditionerAnchor, nodes);
  if (anchor.cols() > 0) {
    state.preconditioner_anchor =
        std::make_shared<const mess::PreconditionerAnchor>(mess::PreconditionerAnchor{
            anchor.cast<float>(),
            std::bit_cast<std::uint64_t>(in.int_attribute(kPreconditionerAnchor, "key"))});
  }
  if (next > 0) {
    state.records =
        read_step_records(in, "/records", runner.steps(), runner.system().particle_count(),
                          runner.system().energy_labels());
  }
  if (state.records.size() != next) {
    throw std::runtime_error("checkpoint " + file.string() + ": records do not match next_step");
  }
  state.next_step = next;
  return state;
}

}  // namespace mresim::mess_protocol
