#include "mresim/io/output_lock.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <ctime>

#include "mresim/io/run_directory.hpp"

namespace mresim::io {

namespace fs = std::filesystem;

namespace {

// The process's own start, taken once (static initialisation happens right at start-up).
const std::time_t process_start = std::time(nullptr);

std::string read_all(int fd) {
  std::string text;
  char buffer[512];
  ::lseek(fd, 0, SEEK_SET);
  for (ssize_t n; (n = ::read(fd, buffer, sizeof buffer)) > 0;) {
    text.append(buffer, static_cast<std::size_t>(n));
  }
  while (!text.empty() && (text.back() == '\n' || text.back() == '\0')) text.pop_back();
  return text.empty() ? std::string("another mresim process") : text;
}

void write_all(int fd, const std::string& text) {
  if (::ftruncate(fd, 0) != 0) return;  // the description only serves messages
  ::lseek(fd, 0, SEEK_SET);
  std::size_t done = 0;
  while (done < text.size()) {
    const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
    if (n <= 0) return;
    done += static_cast<std::size_t>(n);
  }
}

// Whether `fd` is still the file at `path` (the previous owner may have removed the file between
// our open and our flock; locking a removed file would lock nothing).
bool same_file(int fd, const fs::path& path) {
  struct stat by_fd {};
  struct stat by_path {};
  if (::fstat(fd, &by_fd) != 0 || ::stat(path.c_str(), &by_path) != 0) return false;
  return by_fd.st_dev == by_path.st_dev && by_fd.st_ino == by_path.st_ino;
}

}  // namespace

std::string describe_this_process(const std::string& command) {
  char host[256] = {};
  if (::gethostname(host, sizeof host - 1) != 0) std::strcpy(host, "?");
  std::tm utc{};
  ::gmtime_r(&process_start, &utc);
  char started[32];
  std::strftime(started, sizeof started, "%Y-%m-%d %H:%M:%S UTC", &utc);
  return fmt::format("{}, pid {} on host {}, started {}", command, ::getpid(), host, started);
}

fs::path OutputLock::lock_path(const fs::path& final_dir) {
  return final_dir.parent_path() / (final_dir.filename().string() + ".mresim-lock");
}

OutputLock::OutputLock(const fs::path& final_dir, const fs::path& shown, const std::string& command,
                       const std::string& advice)
    : path_(lock_path(final_dir)) {
  // A few tries cover the race with an owner that removes the file while we open it.
  for (int attempt = 0; attempt < 8; ++attempt) {
    fd_ = ::open(path_.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd_ < 0) {
      throw OutputDirectoryError(fmt::format("cannot create the lock file '{}': {}", path_.string(),
                                             std::strerror(errno)));
    }
    if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
      const std::string holder = read_all(fd_);
      ::close(fd_);
      fd_ = -1;
      throw OutputDirectoryError(
          fmt::format("output directory '{}' is in use by {} (lock file '{}'); {}", shown.string(),
                      holder, path_.string(), advice));
    }
    if (same_file(fd_, path_)) {
      write_all(fd_, describe_this_process(command) + "\n");
      return;
    }
    ::close(fd_);
    fd_ = -1;
  }
  throw OutputDirectoryError(
      fmt::format("cannot lock '{}': it keeps being replaced", path_.string()));
}

OutputLock::~OutputLock() {
  if (fd_ < 0) return;
  // Remove while still holding the lock, so that nobody locks the file we are about to drop.
  ::unlink(path_.c_str());
  ::close(fd_);
}

}  // namespace mresim::io
