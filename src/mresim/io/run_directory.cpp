#include "mresim/io/run_directory.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <sys/types.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

namespace mresim::io {

namespace fs = std::filesystem;

namespace {

std::string staging_prefix(const fs::path& final_dir) {
  return final_dir.filename().string() + ".partial-";
}

// Whether a process with this id is running (kill with signal 0 only checks).
bool process_alive(pid_t pid) { return ::kill(pid, 0) == 0 || errno != ESRCH; }

// The staging directories of finished processes for `final_dir`.
std::vector<fs::path> stale_staging(const fs::path& final_dir) {
  const std::string prefix = staging_prefix(final_dir);
  std::vector<fs::path> out;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(final_dir.parent_path(), ec)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind(prefix, 0) != 0) continue;
    const std::string digits = name.substr(prefix.size());
    if (digits.empty() || digits.find_first_not_of("0123456789") != std::string::npos) continue;
    if (!process_alive(static_cast<pid_t>(std::stol(digits)))) out.push_back(entry.path());
  }
  return out;
}

fs::path normalised_final(const fs::path& final_dir) {
  fs::path out = fs::absolute(final_dir).lexically_normal();
  if (out.filename().empty()) out = out.parent_path();  // "results/" -> "results"
  return out;
}

}  // namespace

bool RunDirectory::is_run_directory(const fs::path& dir) {
  std::error_code ec;
  return fs::is_directory(dir, ec) && fs::is_regular_file(dir / kMarkerFile, ec);
}

void RunDirectory::resolve_final(const fs::path& final_dir) {
  shown_ = final_dir;
  final_ = normalised_final(final_dir);
  check_replaceable();
}

fs::path RunDirectory::find_interrupted(const fs::path& final_dir, const fs::path& file) {
  fs::path best;
  fs::file_time_type best_time;
  std::error_code ec;
  for (const fs::path& dir : stale_staging(normalised_final(final_dir))) {
    if (!fs::is_regular_file(dir / file, ec)) continue;
    const fs::file_time_type t = fs::last_write_time(dir / file, ec);
    if (best.empty() || t > best_time) {
      best = dir;
      best_time = t;
    }
  }
  return best;
}

RunDirectory::RunDirectory(const fs::path& final_dir, const fs::path& interrupted_staging) {
  resolve_final(final_dir);
  staging_ = final_.parent_path() / (staging_prefix(final_) + std::to_string(::getpid()));
  std::error_code ec;
  fs::rename(interrupted_staging, staging_, ec);
  if (ec) {
    staging_.clear();  // nothing of ours to remove
    throw OutputDirectoryError(
        fmt::format("cannot take over '{}': {}", interrupted_staging.string(), ec.message()));
  }
}

RunDirectory::RunDirectory(const fs::path& final_dir) {
  resolve_final(final_dir);

  std::error_code ec;
  fs::create_directories(final_.parent_path(), ec);
  if (ec) {
    throw OutputDirectoryError(fmt::format("cannot create output directory '{}': {}",
                                           final_.parent_path().string(), ec.message()));
  }
  remove_stale_staging();
  staging_ = final_.parent_path() / (staging_prefix(final_) + std::to_string(::getpid()));
  fs::remove_all(staging_, ec);
  if (!fs::create_directory(staging_, ec) || ec) {
    throw OutputDirectoryError(
        fmt::format("cannot create output directory '{}': {}", staging_.string(), ec.message()));
  }
}

RunDirectory::~RunDirectory() {
  if (!committed_ && !staging_.empty()) {
    std::error_code ec;
    fs::remove_all(staging_, ec);  // best effort: a destructor must not throw
  }
}

void RunDirectory::check_replaceable() const {
  std::error_code ec;
  if (!fs::exists(fs::symlink_status(final_, ec))) return;
  const bool empty_dir = fs::is_directory(final_, ec) && fs::is_empty(final_, ec);
  if (!empty_dir && !is_run_directory(final_)) {
    throw OutputDirectoryError(fmt::format(
        "output directory '{}' exists and is not an mresim run directory; choose another --out",
        shown_.string()));
  }
}

void RunDirectory::remove_stale_staging() const {
  std::error_code ec;
  for (const fs::path& dir : stale_staging(final_)) fs::remove_all(dir, ec);
}

void RunDirectory::commit() {
  if (committed_) throw std::logic_error("RunDirectory::commit called twice");
  check_replaceable();  // something may have appeared there while we computed
  std::error_code ec;
  if (!fs::exists(fs::symlink_status(final_, ec))) {
    fs::rename(staging_, final_);
  } else if (::renameat2(AT_FDCWD, staging_.c_str(), AT_FDCWD, final_.c_str(), RENAME_EXCHANGE) ==
             0) {
    // The old run now sits at the staging path.
    fs::remove_all(staging_, ec);
  } else {
    // No atomic exchange on this file system: move the old run aside, then ours in.
    const fs::path old =
        final_.parent_path() / (final_.filename().string() + ".old-" + std::to_string(::getpid()));
    fs::remove_all(old, ec);
    fs::rename(final_, old);
    fs::rename(staging_, final_);
    fs::remove_all(old, ec);
  }
  committed_ = true;
}

}  // namespace mresim::io
