#include "mresim/io/run_directory.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <string>
#include <vector>

#include "mresim/io/run_manifest.hpp"

namespace mresim::io {

namespace fs = std::filesystem;

namespace {

std::string staging_prefix(const fs::path& final_dir) {
  return final_dir.filename().string() + ".partial-";
}

fs::path normalised_final(const fs::path& final_dir) {
  fs::path out = fs::absolute(final_dir).lexically_normal();
  if (out.filename().empty()) out = out.parent_path();  // "results/" -> "results"
  return out;
}

// "'a', 'b', 'c' and 4 more" for messages.
std::string first_entries(const std::vector<fs::path>& entries) {
  constexpr std::size_t kShown = 3;
  std::string out;
  for (std::size_t i = 0; i < std::min(entries.size(), kShown); ++i) {
    out += (i > 0 ? ", '" : "'") + entries[i].generic_string() + "'";
  }
  if (entries.size() > kShown) out += fmt::format(" and {} more", entries.size() - kShown);
  return out;
}

// Why mresim may not replace `dir` ("" if it may): it exists and is neither empty nor an mresim
// run directory holding only the files of its manifest.
std::string why_not_replaceable(const fs::path& dir) {
  std::error_code ec;
  if (!fs::exists(fs::symlink_status(dir, ec))) return "";
  if (!fs::is_directory(dir, ec)) return "exists and is not a directory";
  if (fs::is_empty(dir, ec)) return "";
  const std::vector<fs::path> unlisted = run_manifest::unlisted_entries(dir);
  if (unlisted.empty()) return "";
  if (!run_manifest::exists(dir)) {
    return fmt::format("exists and was not written by mresim (it has no {} and holds {})",
                       run_manifest::kFileName, first_entries(unlisted));
  }
  return fmt::format("holds files mresim did not write ({})", first_entries(unlisted));
}

// "<final>.replaced-20261201-195003" (with a counter if that exists too).
fs::path aside_name(const fs::path& final_dir) {
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  ::gmtime_r(&now, &utc);
  char stamp[32];
  std::strftime(stamp, sizeof stamp, "%Y%m%d-%H%M%S", &utc);
  const std::string base = final_dir.filename().string() + ".replaced-" + stamp;
  fs::path candidate = final_dir.parent_path() / base;
  std::error_code ec;
  for (int i = 2; fs::exists(fs::symlink_status(candidate, ec)); ++i) {
    candidate = final_dir.parent_path() / fmt::format("{}-{}", base, i);
  }
  return candidate;
}

}  // namespace

bool RunDirectory::is_run_directory(const fs::path& dir) {
  std::error_code ec;
  return fs::is_directory(dir, ec) && fs::is_regular_file(dir / kMarkerFile, ec);
}

void RunDirectory::claim_final(const fs::path& final_dir, const std::string& command) {
  shown_ = final_dir;
  final_ = normalised_final(final_dir);
  create_parents();
  const std::string advice = command == "mresim resume"
                                 ? "nothing can be resumed while it runs; wait for it to end"
                                 : "wait for it to finish or choose another --out";
  lock_ = std::make_unique<OutputLock>(final_, shown_, command, advice);
}

void RunDirectory::create_parents() {
  std::vector<fs::path> missing;
  std::error_code ec;
  for (fs::path p = final_.parent_path(); !p.empty() && !fs::exists(p, ec); p = p.parent_path()) {
    missing.push_back(p);
    if (p == p.parent_path()) break;
  }
  while (!missing.empty()) {  // outermost first
    const fs::path dir = missing.back();
    missing.pop_back();
    if (!fs::create_directory(dir, ec) && ec) {
      throw OutputDirectoryError(
          fmt::format("cannot create output directory '{}': {}", dir.string(), ec.message()));
    }
    created_parents_.insert(created_parents_.begin(), dir);  // deepest first
  }
}

void RunDirectory::check_replaceable(bool force) {
  const std::string why = why_not_replaceable(final_);
  if (why.empty() || force) return;
  throw OutputDirectoryError(fmt::format(
      "output directory '{}' {}; choose another --out, or add --force to move it aside (it is "
      "renamed, never deleted)",
      shown_.string(), why));
}

std::vector<fs::path> RunDirectory::interrupted_staging() const {
  // Only called while holding the lock: no live run owns any of these.
  const std::string prefix = staging_prefix(final_);
  std::vector<fs::path> out;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(final_.parent_path(), ec)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind(prefix, 0) != 0) continue;
    const std::string digits = name.substr(prefix.size());
    if (digits.empty() || digits.find_first_not_of("0123456789") != std::string::npos) continue;
    if (fs::is_regular_file(entry.path() / kOwnerFile, ec)) out.push_back(entry.path());
  }
  return out;
}

void RunDirectory::remove_interrupted_staging() const {
  std::error_code ec;
  for (const fs::path& dir : interrupted_staging()) fs::remove_all(dir, ec);
}

void RunDirectory::create_staging() {
  const fs::path staging =
      final_.parent_path() / (staging_prefix(final_) + std::to_string(::getpid()));
  std::error_code ec;
  if (!fs::create_directory(staging, ec) || ec) {
    throw OutputDirectoryError(fmt::format("cannot create output directory '{}': {}",
                                           staging.string(),
                                           ec ? ec.message() : std::string("it exists already")));
  }
  staging_ = staging;
  std::ofstream(staging_ / kOwnerFile) << describe_this_process("mresim") << '\n';
}

RunDirectory::RunDirectory(const fs::path& final_dir, Options options) {
  try {
    claim_final(final_dir, "mresim run");
    check_replaceable(options.force);
    force_ = options.force;
    remove_interrupted_staging();
    create_staging();
  } catch (...) {
    release();
    throw;
  }
}

RunDirectory::RunDirectory(const fs::path& final_dir, ForResume /*tag*/) {
  try {
    claim_final(final_dir, "mresim resume");
  } catch (...) {
    release();
    throw;
  }
}

std::unique_ptr<RunDirectory> RunDirectory::resume(const fs::path& final_dir,
                                                   const fs::path& file) {
  std::unique_ptr<RunDirectory> run(new RunDirectory(final_dir, ForResume{}));
  fs::path newest;
  fs::file_time_type newest_time;
  std::error_code ec;
  for (const fs::path& dir : run->interrupted_staging()) {
    if (!fs::is_regular_file(dir / file, ec)) continue;
    const fs::file_time_type t = fs::last_write_time(dir / file, ec);
    if (newest.empty() || t > newest_time) {
      newest = dir;
      newest_time = t;
    }
  }
  const std::string shown = final_dir.string();
  if (newest.empty()) {
    throw OutputDirectoryError(fmt::format(
        "no interrupted run with a checkpoint for '{}' (looked for '{}.partial-<pid>/{}'); start "
        "it again with 'mresim run'",
        shown, shown, file.string()));
  }
  run->check_replaceable(false);
  const fs::path staging =
      run->final_.parent_path() / (staging_prefix(run->final_) + std::to_string(::getpid()));
  if (newest != staging) {
    fs::rename(newest, staging, ec);
    if (ec) {
      throw OutputDirectoryError(
          fmt::format("cannot take over '{}': {}", newest.string(), ec.message()));
    }
  }
  run->staging_ = staging;
  std::ofstream(staging / kOwnerFile) << describe_this_process("mresim") << '\n';
  return run;
}

void RunDirectory::release() {
  std::error_code ec;
  if (!committed_ && !keep_staging_ && !staging_.empty()) fs::remove_all(staging_, ec);
  lock_.reset();  // removes the lock file, which lives in the deepest parent
  for (const fs::path& dir : created_parents_) {
    if (!fs::is_empty(dir, ec) || ec) break;  // something else was put there: keep it
    fs::remove(dir, ec);
  }
  created_parents_.clear();
}

RunDirectory::~RunDirectory() { release(); }

void RunDirectory::replace_final() {
  std::error_code ec;
  if (!why_not_replaceable(final_).empty()) {
    // Only with force (checked by commit): the old directory is kept under another name.
    moved_aside_ = aside_name(final_);
    fs::rename(final_, moved_aside_);
    fs::rename(staging_, final_);
    return;
  }
  if (::renameat2(AT_FDCWD, staging_.c_str(), AT_FDCWD, final_.c_str(), RENAME_EXCHANGE) == 0) {
    // The old run now sits at the staging path. If something was added to it between the check
    // and the exchange, keep it under another name rather than delete it.
    if (!why_not_replaceable(staging_).empty()) {
      moved_aside_ = aside_name(final_);
      fs::rename(staging_, moved_aside_);
    } else {
      fs::remove_all(staging_, ec);
    }
    return;
  }
  // No atomic exchange on this file system: move the old run aside, then ours in.
  const fs::path old = aside_name(final_);
  fs::rename(final_, old);
  fs::rename(staging_, final_);
  fs::remove_all(old, ec);
}

void RunDirectory::commit() {
  if (committed_) throw std::logic_error("RunDirectory::commit called twice");
  const std::string why = why_not_replaceable(final_);
  if (!why.empty() && !force_) {
    // Something appeared there while we computed: keep our results where they are, as a plain
    // directory (without the owner file no later run takes it for an interrupted one).
    keep_staging_ = true;
    std::error_code ec;
    fs::remove(staging_ / kOwnerFile, ec);
    throw OutputDirectoryError(fmt::format(
        "output directory '{}' {} (it changed while the run computed); nothing was replaced, the "
        "results are in '{}'",
        shown_.string(), why, staging_.string()));
  }
  std::error_code ec;
  fs::remove(staging_ / kOwnerFile, ec);
  run_manifest::write(staging_);
  if (!fs::exists(fs::symlink_status(final_, ec))) {
    fs::rename(staging_, final_);
  } else {
    replace_final();
  }
  committed_ = true;
  created_parents_.clear();  // they hold the run now
}

}  // namespace mresim::io
