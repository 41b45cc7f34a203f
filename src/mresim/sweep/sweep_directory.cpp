#include "mresim/sweep/sweep_directory.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <fstream>
#include <iterator>
#include <sstream>
#include <stdexcept>

#include "mresim/io/hdf5_reader.hpp"
#include "mresim/io/run_directory.hpp"

namespace mresim::sweep {

namespace fs = std::filesystem;

namespace {

std::string read_text(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Writes `text` to `file` whole: into a temporary of this process, then renamed, so that a
// reader (or a concurrent writer of the same text) never sees half a file.
void write_whole(const fs::path& file, const std::string& text) {
  const fs::path temporary = fs::path(fmt::format("{}.tmp-{}", file.string(), ::getpid()));
  {
    std::ofstream out(temporary, std::ios::binary);
    out << text;
    if (!out.flush()) throw std::runtime_error("cannot write " + temporary.string());
  }
  fs::rename(temporary, file);
}

// The value of a TOML text as JSON: numbers, strings and booleans as such, anything else
// (arrays, tables, dates) as its TOML text.
nlohmann::json json_value(const std::string& toml_text) {
  try {
    const toml::table t = toml::parse("v = " + toml_text);
    const toml::node& v = *t.get("v");
    if (const auto* i = v.as_integer()) return i->get();
    if (const auto* f = v.as_floating_point()) return f->get();
    if (const auto* b = v.as_boolean()) return b->get();
    if (const auto* s = v.as_string()) return s->get();
  } catch (const toml::parse_error&) {  // cannot happen for toml_value_text(); keep the text
  }
  return toml_text;
}

std::string last_error_line(const fs::path& log) {
  std::istringstream lines(read_text(log));
  std::string line;
  std::string last;
  std::string last_error;
  while (std::getline(lines, line)) {
    if (line.empty()) continue;
    last = line;
    if (line.find("error") != std::string::npos) last_error = line;
  }
  return last_error.empty() ? last : last_error;
}

}  // namespace

std::string point_name(std::size_t index, std::size_t count) {
  const std::size_t width = std::max<std::size_t>(4, std::to_string(count - 1).size());
  return fmt::format("point-{:0{}}", index, width);
}

nlohmann::json sweep_record(const SweepSpec& spec, const std::string& run_file) {
  nlohmann::json points = nlohmann::json::array();
  for (const SweepPoint& p : spec.points) {
    nlohmann::json parameters = nlohmann::json::object();
    for (std::size_t k = 0; k < spec.keys.size(); ++k) {
      parameters[spec.keys[k]] = json_value(p.values[k]);
    }
    points.push_back({{"index", p.index},
                      {"directory", point_name(p.index, spec.points.size())},
                      {"parameters", parameters},
                      {"set", p.overrides}});
  }
  return {{"format", "mresim sweep 1"},
          {"run_file", fs::path(run_file).filename().string()},
          {"base_file", kBaseFile},
          {"keys", spec.keys},
          {"points", points}};
}

bool is_sweep_directory(const fs::path& dir) {
  std::error_code ec;
  return fs::is_regular_file(dir / kRecordFile, ec);
}

void prepare_sweep_directory(const fs::path& dir, const SweepSpec& spec,
                             const std::string& run_file) {
  const std::string record = sweep_record(spec, run_file).dump(1) + "\n";
  std::error_code ec;
  if (is_sweep_directory(dir)) {
    if (read_text(dir / kRecordFile) != record || read_text(dir / kBaseFile) != spec.base_text) {
      throw io::OutputDirectoryError(fmt::format(
          "'{}' holds another sweep (its sweep.json or base.toml differ from what {} gives); "
          "use another --out, or move that directory away",
          dir.string(), run_file));
    }
  } else if (fs::exists(dir, ec)) {
    if (!fs::is_directory(dir, ec)) {
      throw io::OutputDirectoryError(
          fmt::format("--out '{}' exists and is not a directory", dir.string()));
    }
    if (!fs::is_empty(dir, ec)) {
      throw io::OutputDirectoryError(
          fmt::format("--out '{}' is a directory with files but no sweep.json, not a sweep "
                      "directory of mresim; use another --out",
                      dir.string()));
    }
  }
  fs::create_directories(dir / kLogsDir);
  write_whole(dir / kBaseFile, spec.base_text);
  write_whole(dir / kRecordFile, record);
}

const char* status_name(PointStatus status) {
  switch (status) {
    case PointStatus::finished:
      return "finished";
    case PointStatus::invalid_results:
      return "invalid_results";
    case PointStatus::failed:
      return "failed";
    case PointStatus::pending:
      return "pending";
  }
  return "pending";
}

fs::path log_file(const fs::path& dir, std::size_t index, std::size_t count) {
  return dir / kLogsDir / (point_name(index, count) + ".log");
}

fs::path status_file(const fs::path& dir, std::size_t index, std::size_t count) {
  return dir / kLogsDir / (point_name(index, count) + ".status");
}

void write_point_status(const fs::path& dir, std::size_t index, std::size_t count,
                        int exit_status) {
  write_whole(status_file(dir, index, count), fmt::format("{}\n", exit_status));
}

PointState point_state(const fs::path& dir, std::size_t index, std::size_t count) {
  PointState state;
  std::error_code ec;
  const fs::path status = status_file(dir, index, count);
  if (fs::is_regular_file(status, ec)) {
    try {
      state.exit_status = std::stoi(read_text(status));
    } catch (const std::exception&) {  // unreadable: unknown
    }
  }
  const fs::path run = dir / point_name(index, count);
  if (io::RunDirectory::is_run_directory(run)) {
    // Every run writes the root attribute invalid_results ("" when all results are valid).
    const io::Hdf5Reader results(run / io::RunDirectory::kMarkerFile);
    state.message = results.string_attribute("/", "invalid_results");
    state.status = state.message.empty() ? PointStatus::finished : PointStatus::invalid_results;
    return state;
  }
  if (state.exit_status > 0) {
    state.status = PointStatus::failed;
    state.message = last_error_line(log_file(dir, index, count));
  }
  return state;
}

nlohmann::json read_sweep_record(const fs::path& dir) {
  if (!is_sweep_directory(dir)) {
    throw io::OutputDirectoryError(fmt::format(
        "'{}' is not a sweep directory (no sweep.json in it; made by 'mresim sweep FILE --out "
        "DIR')",
        dir.string()));
  }
  try {
    nlohmann::json record = nlohmann::json::parse(read_text(dir / kRecordFile));
    if (!record.contains("keys") || !record.contains("points")) {
      throw std::runtime_error("no keys or points");
    }
    return record;
  } catch (const std::exception& e) {
    throw io::OutputDirectoryError(fmt::format("'{}' is not a valid sweep record: {}",
                                               (dir / kRecordFile).string(), e.what()));
  }
}

}  // namespace mresim::sweep
