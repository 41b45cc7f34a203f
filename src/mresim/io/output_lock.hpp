#pragma once

#include <filesystem>
#include <string>

namespace mresim::io {

// An exclusive lock on one output directory, held for as long as a run or resume writes to it.
//
// The lock is flock(2) on "<parent>/<name>.mresim-lock" beside the output directory. The kernel
// releases it when the process ends in any way (SIGKILL, out of memory, power cut of a node
// that shares the file system), so a lock that can be taken proves that no other mresim is
// writing this directory: no process ids are compared, and a reused pid (mresim as pid 1 in a
// container) cannot make an interrupted run look alive or a live one look dead. The file holds
// the owner's description for messages; the owner removes it on release.
class OutputLock {
 public:
  // Takes the lock for `final_dir` (absolute, normalised) for `command` ("mresim run").
  // Throws OutputDirectoryError naming the directory as `shown`, the process that holds it
  // ("is in use by mresim run, pid 12 on host n01, started ...") and `advice`.
  OutputLock(const std::filesystem::path& final_dir, const std::filesystem::path& shown,
             const std::string& command, const std::string& advice);
  ~OutputLock();
  OutputLock(const OutputLock&) = delete;
  OutputLock& operator=(const OutputLock&) = delete;

  [[nodiscard]] const std::filesystem::path& path() const { return path_; }

  // "<parent>/<name>.mresim-lock" for `final_dir`.
  static std::filesystem::path lock_path(const std::filesystem::path& final_dir);

 private:
  std::filesystem::path path_;
  int fd_ = -1;
};

// "mresim run, pid 1234 on host n01, started 2026-12-01 19:50:03 UTC": who this process is, for
// lock files and the owner file of staging directories.
std::string describe_this_process(const std::string& command);

}  // namespace mresim::io
