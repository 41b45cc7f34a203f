#include "cli/finished_run.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cstdio>
#include <exception>
#include <mresim/core/version.hpp>
#include <sstream>
#include <stdexcept>

#include "cli/commands.hpp"
#include "mresim/io/hdf5_reader.hpp"
#include "mresim/io/metadata.hpp"
#include "mresim/io/run_directory.hpp"
#include "mresim/mess/protocols/protocol.hpp"

namespace mresim::cli {

namespace fs = std::filesystem;

namespace {

// A root attribute, "" when the file has none (a run without overrides has no input_overrides).
std::string optional_attribute(const io::Hdf5Reader& file, const char* name) {
  try {
    return file.string_attribute("/", name);
  } catch (const std::runtime_error&) {
    return "";
  }
}

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    if (!line.empty()) out.push_back(line);
  }
  return out;
}

}  // namespace

config::TableReader finished_run_file(const fs::path& dir, const std::vector<std::string>& more,
                                      const std::string& command) {
  if (!io::RunDirectory::is_run_directory(dir)) {
    throw io::OutputDirectoryError(fmt::format(
        "'{}' holds no finished mresim run (no {}); {} continues a run that 'mresim run' "
        "finished",
        dir.string(), io::RunDirectory::kMarkerFile, command));
  }
  const io::Hdf5Reader results(dir / io::RunDirectory::kMarkerFile);
  const std::string run_type = optional_attribute(results, "run_type");
  const std::vector<std::string> types = mess_protocol::protocol_names();
  if (std::find(types.begin(), types.end(), run_type) == types.end()) {
    throw io::OutputDirectoryError(
        fmt::format("'{}' is a run of type '{}'; {} continues the 3D runs only (mess_*)",
                    dir.string(), run_type, command));
  }
  const std::string effective = results.string_attribute("/", "input_toml");
  const std::string name = results.string_attribute("/", "input_file");
  const std::vector<std::string> own = lines_of(optional_attribute(results, "input_overrides"));
  const std::string as_written = optional_attribute(results, "input_file_toml");
  if (!own.empty() && !as_written.empty()) {
    // The file as written and every override in order, so that the results record them all.
    std::vector<std::string> all = own;
    all.insert(all.end(), more.begin(), more.end());
    const auto check = config::TableReader::parse_string(as_written, name, own);
    if (check.source_text() == effective) {
      return config::TableReader::parse_string(as_written, name, all);
    }
  }
  return more.empty() ? config::TableReader::parse_string(effective, name)
                      : config::TableReader::parse_string(effective, name, more);
}

mess_protocol::HistoryEntry new_history_entry(const std::string& kind,
                                              const std::vector<std::string>& command_words,
                                              const std::vector<std::string>& overrides) {
  mess_protocol::HistoryEntry entry;
  entry.kind = kind;
  entry.time_utc = io::utc_timestamp();
  entry.command_line = mess_protocol::command_line_text(command_words);
  entry.overrides = overrides;
  entry.mresim_version = kVersion;
  return entry;
}

int execute_on_finished_run(const fs::path& dir, const config::TableReader& root,
                            const app::RunPlan& plan, const std::string& announcement, long threads,
                            bool no_plot) {
  const mess::MpiJob job = mess::mpi_job();
  const std::string run_type = app::read_run_settings(root).type;
  if (job.size > 1) {
    refuse_unsplittable_plan(plan, run_type);
    if (job.rank > 0) return participate_in_run(root, plan, threads, job, {});
  }
  try {
    io::RunDirectory run_dir(dir);
    std::printf("%s\n", announcement.c_str());
    std::fflush(stdout);
    return execute_and_publish(root, plan, run_type, run_dir, threads, no_plot, job);
  } catch (const std::exception& e) {
    end_job_on_error(e, job);
    throw;
  }
}

}  // namespace mresim::cli
