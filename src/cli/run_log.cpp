// --quiet and --log FILE of `mresim run` and `mresim resume`: where the run's messages go
// (app::RunOutput). The log file is checked before anything is read, so that a path the run
// would itself delete or move aside is refused instead of silently lost.

#include <fmt/format.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <string>

#include "cli/commands.hpp"
#include "mresim/app/run_output.hpp"
#include "mresim/io/run_directory.hpp"

namespace mresim::cli {

namespace fs = std::filesystem;

namespace {

struct FileCloser {
  void operator()(std::FILE* f) const { std::fclose(f); }
};

// The open log: lives until the process ends (every line is flushed as it is written).
std::unique_ptr<std::FILE, FileCloser>& open_log() {
  static std::unique_ptr<std::FILE, FileCloser> log;
  return log;
}

fs::path absolute_normal(const fs::path& p) { return fs::weakly_canonical(fs::absolute(p)); }

// Whether `inner` is `outer` or lies below it.
bool is_within(const fs::path& inner, const fs::path& outer) {
  auto i = inner.begin();
  for (auto o = outer.begin(); o != outer.end(); ++o, ++i) {
    if (o->empty()) continue;  // a trailing separator
    if (i == inner.end() || *i != *o) return false;
  }
  return true;
}

// Why `log` cannot be the log of a run into `out_dir`; empty if it can.
std::string log_path_problem(const fs::path& log, const fs::path& out_dir) {
  if (log.empty()) return "must name a file";
  const fs::path file = absolute_normal(log);
  const fs::path out = absolute_normal(out_dir);
  // The run computes in DIR.partial-<pid> and then replaces DIR with it: a log in either would
  // be deleted or moved aside with the directory.
  const std::string staging_prefix = out.filename().string() + ".partial-";
  for (fs::path dir = file.parent_path(); !dir.empty(); dir = dir.parent_path()) {
    if (dir.parent_path() == out.parent_path() &&
        dir.filename().string().rfind(staging_prefix, 0) == 0) {
      return fmt::format("lies in the staging directory of '{}'", out_dir.string());
    }
    if (dir == dir.parent_path()) break;
  }
  if (is_within(file, out)) {
    return fmt::format(
        "lies inside the output directory '{}', which the run replaces; write the log "
        "elsewhere, e.g. next to it",
        out_dir.string());
  }
  return "";
}

}  // namespace

void add_output_options(CLI::App& command, OutputOptions& options) {
  command.add_flag("--quiet,-q", options.quiet,
                   "Print nothing but errors (no progress, set-up, step lines or warnings)");
  command
      .add_option("--log", options.log,
                  "Also write the progress lines (set-up, one per step, heartbeats, warnings, "
                  "errors) to FILE, each flushed at once; not inside the output directory")
      ->type_name("FILE");
}

void configure_output(const OutputOptions& options, const fs::path& out_dir, bool append) {
  app::RunOutput::Options output;
  if (options.quiet) output.stream = nullptr;
  if (options.log) {
    const std::string& log = *options.log;
    if (const std::string problem = log_path_problem(log, out_dir); !problem.empty()) {
      throw io::OutputDirectoryError(fmt::format("--log '{}': {}", log, problem));
    }
    errno = 0;
    std::FILE* file = std::fopen(log.c_str(), append ? "a" : "w");
    if (file == nullptr) {
      throw io::OutputDirectoryError(
          fmt::format("--log '{}': cannot write it: {}", log, std::strerror(errno)));
    }
    open_log().reset(file);
    output.log = file;
  }
  app::configure_run_output(output);
}

}  // namespace mresim::cli
