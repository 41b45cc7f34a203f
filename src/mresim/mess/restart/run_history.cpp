#include "mresim/mess/restart/run_history.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <sstream>

#include "mresim/mess/outputs/step_records_io.hpp"
#include "mresim/mess/protocols/step_plan.hpp"

namespace mresim::mess_protocol {

namespace fs = std::filesystem;

namespace {

std::string joined_lines(const std::vector<std::string>& lines) {
  std::string out;
  for (const std::string& l : lines) out += (out.empty() ? "" : "\n") + l;
  return out;
}

std::vector<std::string> split_lines(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) out.push_back(line);
  return out;
}

// The replaced records keep the step they had (a later extend may have planned another step
// under the same index), so the StepSpec is read from the datasets, not from a plan.
std::vector<StepRecord> read_replaced(const io::Hdf5Reader& file, const std::string& group,
                                      const ProtocolRunner& runner) {
  const std::vector<std::int64_t> index = file.ints(group + "/index");
  const std::int64_t largest = index.empty() ? 0 : *std::max_element(index.begin(), index.end());
  std::vector<StepSpec> any(static_cast<std::size_t>(std::max<std::int64_t>(largest, 0)) + 1);
  for (std::size_t i = 0; i < any.size(); ++i) any[i].index = i;
  std::vector<StepRecord> records = read_step_records(
      file, group, any, runner.system().particle_count(), runner.system().energy_labels());
  const std::vector<std::int64_t> field_index = file.ints(group + "/field_index");
  const std::vector<std::int64_t> load_index = file.ints(group + "/load_index");
  const std::vector<double> load_value = file.doubles(group + "/load_value");
  const std::vector<double> field = file.doubles(group + "/field");
  for (std::size_t i = 0; i < records.size(); ++i) {
    StepSpec& s = records[i].step;
    s.field_index = static_cast<std::size_t>(field_index.at(i));
    s.load_index = static_cast<std::size_t>(load_index.at(i));
    s.load_value = load_value.at(i);
    s.field = Eigen::Vector3d(field.at(3 * i), field.at(3 * i + 1), field.at(3 * i + 2));
  }
  return records;
}

}  // namespace

void write_history(io::Hdf5File& file, const std::vector<HistoryEntry>& entries,
                   const ProtocolRunner& runner) {
  if (entries.empty()) return;
  file.write_int_attribute("/history", "entries", static_cast<std::int64_t>(entries.size()));
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const HistoryEntry& e = entries[i];
    const std::string g = fmt::format("/history/{}", i);
    file.write_string_attribute(g, "kind", e.kind);
    file.write_string_attribute(g, "time_utc", e.time_utc);
    file.write_string_attribute(g, "command_line", e.command_line);
    file.write_string_attribute(g, "overrides", joined_lines(e.overrides));
    file.write_string_attribute(g, "mresim_version", e.mresim_version);
    file.write_string_attribute(g, "previous_input_toml", e.previous_input_toml);
    file.write_int_vector(g + "/added_steps", e.added_steps);
    file.write_int_vector(g + "/recomputed_steps", e.recomputed_steps);
    file.write_int_vector(g + "/replaced_steps", e.replaced_steps);
    if (!e.replaced.empty()) {
      write_step_records(file, g + "/replaced", e.replaced, runner.system().particle_count(),
                         load_unit(runner.spec()), *runner.system().energy_labels());
    }
  }
}

std::vector<HistoryEntry> read_history(const io::Hdf5Reader& file, const ProtocolRunner& runner) {
  std::vector<HistoryEntry> entries;
  if (!file.exists("/history")) return entries;
  const std::int64_t count = file.int_attribute("/history", "entries");
  for (std::int64_t i = 0; i < count; ++i) {
    const std::string g = fmt::format("/history/{}", i);
    HistoryEntry e;
    e.kind = file.string_attribute(g, "kind");
    e.time_utc = file.string_attribute(g, "time_utc");
    e.command_line = file.string_attribute(g, "command_line");
    e.overrides = split_lines(file.string_attribute(g, "overrides"));
    e.mresim_version = file.string_attribute(g, "mresim_version");
    e.previous_input_toml = file.string_attribute(g, "previous_input_toml");
    e.added_steps = file.ints(g + "/added_steps");
    e.recomputed_steps = file.ints(g + "/recomputed_steps");
    e.replaced_steps = file.ints(g + "/replaced_steps");
    if (file.exists(g + "/replaced")) e.replaced = read_replaced(file, g + "/replaced", runner);
    entries.push_back(std::move(e));
  }
  return entries;
}

void write_pending_history(const fs::path& staging_dir, const std::vector<HistoryEntry>& entries,
                           const ProtocolRunner& runner) {
  const fs::path file = staging_dir / kPendingHistoryFile;
  const fs::path temporary = fs::path(file.string() + ".tmp");
  {
    io::Hdf5File out(temporary);
    write_history(out, entries, runner);
    out.close();
  }
  fs::rename(temporary, file);
}

void publish_pending_history(const fs::path& staging_dir, io::Hdf5File& results,
                             const ProtocolRunner& runner) {
  const fs::path file = staging_dir / kPendingHistoryFile;
  std::error_code ec;
  if (!fs::exists(file, ec)) return;
  std::vector<HistoryEntry> entries;
  {
    const io::Hdf5Reader in(file);
    entries = read_history(in, runner);
  }
  write_history(results, entries, runner);
  fs::remove(file, ec);
}

std::string command_line_text(const std::vector<std::string>& words) {
  std::string out;
  for (const std::string& w : words) {
    const bool plain = !w.empty() && w.find_first_of(" \t\"'$\\") == std::string::npos;
    out += (out.empty() ? "" : " ") + (plain ? w : "'" + w + "'");
  }
  return out;
}

}  // namespace mresim::mess_protocol
