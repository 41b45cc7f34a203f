#pragma once

#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "mresim/io/output_lock.hpp"

namespace mresim::io {

// The user asked for an output directory that mresim must not touch (exit status 2: nothing was
// computed and nothing was written).
struct OutputDirectoryError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// An output directory that is either complete or absent, never half-written, and never one that
// holds files mresim did not write.
//
// - Locking: the output directory is locked (OutputLock) from the constructor to the
//   destructor, so two runs or resumes to one directory cannot overlap; the second is refused
//   with the first one's pid, host and start time.
// - Staging: everything is written to "<final>.partial-<pid>" beside the final directory, with
//   an owner file naming the process; commit() writes the manifest (run_manifest.hpp) and moves
//   the directory into place in one rename. Without commit() (an error, an exception) the
//   staging directory is removed, and so are the parent directories the constructor created.
// - Interrupted runs: a run killed outright leaves its staging directory. Since a live run
//   always holds the lock, every staging directory found while holding it is an interrupted
//   one, whatever its pid: `resume` takes it over, a new `run` removes it.
// - Replacing: an existing final directory is replaced only if it is empty or an mresim run
//   directory holding nothing but the files of its manifest. Anything else is refused, or with
//   `force` moved aside to "<final>.replaced-<time>" (never deleted).
class RunDirectory {
 public:
  static constexpr const char* kMarkerFile = "results.h5";
  // In a staging directory: who created it (describe_this_process).
  static constexpr const char* kOwnerFile = ".mresim-owner";

  struct Options {
    bool force = false;  // move an unrecognised existing final directory aside instead of refusing
  };

  // A new run to `final_dir`. Throws OutputDirectoryError if the directory is locked by another
  // process, exists and is not replaceable, or if the staging directory cannot be created.
  explicit RunDirectory(const std::filesystem::path& final_dir)
      : RunDirectory(final_dir, Options{}) {}
  RunDirectory(const std::filesystem::path& final_dir, Options options);

  // Resuming: takes the lock, then takes over the newest interrupted staging directory of
  // `final_dir` that contains `file` (a checkpoint), keeping its contents. Throws
  // OutputDirectoryError if the run is still going on, or if there is nothing to resume.
  static std::unique_ptr<RunDirectory> resume(const std::filesystem::path& final_dir,
                                              const std::filesystem::path& file);

  ~RunDirectory();
  RunDirectory(const RunDirectory&) = delete;
  RunDirectory& operator=(const RunDirectory&) = delete;

  // Where to write outputs until commit().
  [[nodiscard]] const std::filesystem::path& path() const { return staging_; }
  [[nodiscard]] const std::filesystem::path& final_path() const { return final_; }
  // The final directory as the user gave it (for messages).
  [[nodiscard]] const std::filesystem::path& shown_path() const { return shown_; }
  // Set by the constructor when `force` moved an existing directory aside.
  [[nodiscard]] const std::filesystem::path& moved_aside() const { return moved_aside_; }

  // Moves the staging directory to the final path, replacing an earlier run atomically (Linux
  // renameat2 RENAME_EXCHANGE; a two-step rename where the file system lacks it). Close every
  // file inside first. If the final directory gained files mresim did not write while the run
  // computed, nothing is replaced: the results stay in the staging directory and
  // OutputDirectoryError says where.
  void commit();
  // Whether commit() has published the results.
  [[nodiscard]] bool committed() const { return committed_; }

  // The run was interrupted after writing a checkpoint: keep the staging directory (for
  // `mresim resume`) instead of removing it.
  void keep_for_resume() { keep_staging_ = true; }

  // Whether `dir` holds an mresim run directory (a directory containing results.h5).
  static bool is_run_directory(const std::filesystem::path& dir);

 private:
  struct ForResume {};
  RunDirectory(const std::filesystem::path& final_dir, ForResume tag);

  void claim_final(const std::filesystem::path& final_dir, const std::string& command);
  void check_replaceable(bool force);
  void create_parents();
  void create_staging();
  void remove_interrupted_staging() const;
  [[nodiscard]] std::vector<std::filesystem::path> interrupted_staging() const;
  void replace_final();
  void release();  // removes what an uncommitted run created and drops the lock

  std::filesystem::path shown_;  // as the user gave it, for messages
  std::filesystem::path final_;
  std::filesystem::path staging_;
  std::filesystem::path moved_aside_;
  std::vector<std::filesystem::path> created_parents_;  // deepest first
  std::unique_ptr<OutputLock> lock_;
  bool force_ = false;
  bool committed_ = false;
  bool keep_staging_ = false;
};

}  // namespace mresim::io
