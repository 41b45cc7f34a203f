#include "mresim/io/run_manifest.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <fstream>
#include <set>
#include <stdexcept>

namespace mresim::io::run_manifest {

namespace fs = std::filesystem;

namespace {

constexpr const char* kHeader =
    "# files written by mresim; a run directory is replaced only if it "
    "holds nothing else";

std::set<std::string> read_entries(const fs::path& dir) {
  std::set<std::string> entries;
  std::ifstream in(dir / kFileName);
  std::string line;
  while (std::getline(in, line)) {
    if (!line.empty() && line.front() != '#') entries.insert(line);
  }
  return entries;
}

std::set<std::string> files_below(const fs::path& dir, const fs::path& subdir,
                                  fs::file_time_type since = fs::file_time_type::min()) {
  std::set<std::string> files;
  std::error_code ec;
  const fs::path base = dir.lexically_normal();
  const fs::path top = (dir / subdir).lexically_normal();
  if (!fs::is_directory(top, ec)) return files;
  for (auto it = fs::recursive_directory_iterator(top, ec); !ec && it != fs::end(it);
       it.increment(ec)) {
    if (!it->is_regular_file(ec) || it->last_write_time(ec) < since) continue;
    const fs::path relative = it->path().lexically_normal().lexically_relative(base);
    if (relative != kFileName) files.insert(relative.generic_string());
  }
  return files;
}

void write_entries(const fs::path& dir, const std::set<std::string>& entries) {
  const fs::path target = dir / kFileName;
  const fs::path temporary = dir / fmt::format("{}.tmp-{}", kFileName, ::getpid());
  {
    std::ofstream out(temporary, std::ios::trunc);
    out << kHeader << '\n';
    for (const std::string& entry : entries) out << entry << '\n';
    out.flush();
    if (!out) throw std::runtime_error("cannot write '" + temporary.string() + "'");
  }
  fs::rename(temporary, target);
}

}  // namespace

void write(const fs::path& dir) { write_entries(dir, files_below(dir, ".")); }

void add_files_below(const fs::path& dir, const fs::path& subdir, fs::file_time_type since) {
  if (!run_manifest::exists(dir)) return;
  std::set<std::string> entries = read_entries(dir);
  entries.merge(files_below(dir, subdir, since));
  write_entries(dir, entries);
}

bool exists(const fs::path& dir) {
  std::error_code ec;
  return fs::is_regular_file(dir / kFileName, ec);
}

std::vector<fs::path> unlisted_entries(const fs::path& dir) {
  const std::set<std::string> listed = read_entries(dir);
  // Directories that hold a listed file are ours too.
  std::set<std::string> listed_dirs;
  for (const std::string& entry : listed) {
    for (fs::path p = fs::path(entry).parent_path(); !p.empty(); p = p.parent_path()) {
      listed_dirs.insert(p.generic_string());
    }
  }
  std::vector<fs::path> unlisted;
  std::error_code ec;
  for (auto it = fs::recursive_directory_iterator(dir, ec); !ec && it != fs::end(it);
       it.increment(ec)) {
    const std::string relative = it->path().lexically_relative(dir).generic_string();
    if (relative == kFileName) continue;
    const bool is_dir = it->is_directory(ec) && !it->is_symlink(ec);
    if (is_dir ? listed_dirs.contains(relative) : listed.contains(relative)) continue;
    unlisted.emplace_back(relative);
    if (is_dir) it.disable_recursion_pending();  // its contents are unlisted with it
  }
  std::sort(unlisted.begin(), unlisted.end());
  return unlisted;
}

}  // namespace mresim::io::run_manifest
