#pragma once

#include <filesystem>
#include <stdexcept>

namespace mresim::io {

// The user asked for an output directory that mresim must not touch (exit status 2: nothing was
// computed and nothing was written).
struct OutputDirectoryError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// An output directory that is either complete or absent, never half-written.
//
// Everything is written to a staging directory "<final>.partial-<pid>" next to the final one;
// commit() moves it into place in one rename. If the object is destroyed without commit() (an
// error, an exception) the staging directory is removed. A run killed outright (Ctrl-C, out of
// memory) leaves its staging directory behind; the next run to the same output removes it.
//
// An existing final directory is replaced only if it is an earlier mresim run (it contains
// results.h5) or is empty; anything else is refused in the constructor, before any work.
class RunDirectory {
 public:
  static constexpr const char* kMarkerFile = "results.h5";

  // Throws OutputDirectoryError if `final_dir` exists and is not replaceable, or if the staging
  // directory cannot be created.
  explicit RunDirectory(const std::filesystem::path& final_dir);

  // Resuming an interrupted run: takes over `interrupted_staging` (found by find_interrupted)
  // as this process's staging directory, keeping its contents. Same checks as above.
  RunDirectory(const std::filesystem::path& final_dir,
               const std::filesystem::path& interrupted_staging);

  // The staging directory of an interrupted run to `final_dir` (its process no longer exists)
  // that contains `file`; the most recently modified one if there are several; empty if none.
  static std::filesystem::path find_interrupted(const std::filesystem::path& final_dir,
                                                const std::filesystem::path& file);
  ~RunDirectory();
  RunDirectory(const RunDirectory&) = delete;
  RunDirectory& operator=(const RunDirectory&) = delete;

  // Where to write outputs until commit().
  [[nodiscard]] const std::filesystem::path& path() const { return staging_; }
  [[nodiscard]] const std::filesystem::path& final_path() const { return final_; }
  // The final directory as the user gave it (for messages).
  [[nodiscard]] const std::filesystem::path& shown_path() const { return shown_; }

  // Moves the staging directory to the final path, replacing an earlier run atomically (Linux
  // renameat2 RENAME_EXCHANGE; a two-step rename where the file system lacks it). Close every
  // file inside first.
  void commit();

  // Whether `dir` holds an earlier mresim run (a directory containing results.h5).
  static bool is_run_directory(const std::filesystem::path& dir);

 private:
  void resolve_final(const std::filesystem::path& final_dir);
  void check_replaceable() const;
  void remove_stale_staging() const;

  std::filesystem::path shown_;  // as the user gave it, for messages
  std::filesystem::path final_;
  std::filesystem::path staging_;
  bool committed_ = false;
};

}  // namespace mresim::io
