#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace mresim::io::run_manifest {

// The list of files mresim wrote into a run directory, kept in the directory itself as
// ".mresim-manifest" (one relative path per line after a header line).
//
// It is what makes replacing an earlier run safe: a directory is mresim's to replace only if
// it has a manifest and holds nothing the manifest does not list. A file the user added (notes,
// the run file, a thesis draft) or a directory that merely contains something named results.h5
// is never deleted.

inline constexpr const char* kFileName = ".mresim-manifest";

// Writes the manifest of `dir`: every regular file below it (the manifest itself excluded),
// written atomically (temporary file + rename).
void write(const std::filesystem::path& dir);

// Adds every regular file below `dir / subdir` last written at or after `since` to the manifest
// of `dir` (figures drawn after the run was committed). Does nothing if `dir` has no manifest.
void add_files_below(const std::filesystem::path& dir, const std::filesystem::path& subdir,
                     std::filesystem::file_time_type since);

// Whether `dir` has a manifest.
bool exists(const std::filesystem::path& dir);

// The entries below `dir` that its manifest does not list (files and directories; directories
// only if no listed file is inside), as paths relative to `dir`, sorted. Without a manifest,
// every entry.
std::vector<std::filesystem::path> unlisted_entries(const std::filesystem::path& dir);

}  // namespace mresim::io::run_manifest
