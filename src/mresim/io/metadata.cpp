#include "mresim/io/metadata.hpp"

#include <unistd.h>

#include <array>
#include <ctime>
#include <mresim/core/git_describe.hpp>
#include <mresim/core/version.hpp>

#include "mresim/app/command_line.hpp"

namespace mresim::io {

std::string utc_timestamp() {
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);
  char buffer[32];
  std::strftime(buffer, sizeof buffer, "%Y-%m-%dT%H:%M:%SZ", &utc);
  return buffer;
}

std::string host_name() {
  std::array<char, 256> buffer{};
  if (gethostname(buffer.data(), buffer.size() - 1) != 0 || buffer[0] == '\0') return "unknown";
  return buffer.data();
}

void write_run_metadata(Hdf5File& file, const config::TableReader& root,
                        const std::string& run_type) {
  file.write_string_attribute("/", "mresim_version", kVersion);
  file.write_string_attribute("/", "mresim_git", kGitDescribe);
  file.write_string_attribute("/", "host_name", host_name());
  file.write_string_attribute("/", "command_line", app::command_line());
  file.write_string_attribute("/", "run_type", run_type);
  file.write_string_attribute("/", "input_toml", root.source_text());
  file.write_string_attribute("/", "input_file", root.source_name());
  file.write_string_attribute("/", "created_utc", utc_timestamp());
  if (!root.overrides().empty()) {
    std::string lines;
    for (const std::string& o : root.overrides()) lines += o + "\n";
    file.write_string_attribute("/", "input_overrides", lines);
    file.write_string_attribute("/", "input_file_toml", root.file_text());
  }
}

}  // namespace mresim::io
