#pragma once

// Running a program (usually the built `mresim`) as a child process from a test: started in a
// directory, stdin from /dev/null, stdout and stderr to files, so that a test can signal it,
// race it against another one or time it out.

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <filesystem>
#include <string>
#include <vector>

namespace mresim::testing {

// Starts `program args...` in `dir`; `out` and `err` are created (relative to `dir` unless
// absolute). Returns the child's pid (-1 if fork failed).
inline pid_t start_child(const std::filesystem::path& program, const std::vector<std::string>& args,
                         const std::filesystem::path& dir, const std::filesystem::path& out,
                         const std::filesystem::path& err) {
  std::vector<std::string> words{program.string()};
  words.insert(words.end(), args.begin(), args.end());
  std::vector<char*> argv;
  argv.reserve(words.size() + 1);
  for (auto& w : words) argv.push_back(w.data());
  argv.push_back(nullptr);
  const std::string out_file = (dir / out).string();
  const std::string err_file = (dir / err).string();
  const pid_t pid = ::fork();
  if (pid == 0) {
    const int in_fd = ::open("/dev/null", O_RDONLY);
    const int out_fd = ::open(out_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
    const int err_fd = ::open(err_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
    if (in_fd < 0 || out_fd < 0 || err_fd < 0 || ::chdir(dir.c_str()) != 0) ::_exit(127);
    ::dup2(in_fd, 0);
    ::dup2(out_fd, 1);
    ::dup2(err_fd, 2);
    ::execv(argv[0], argv.data());
    ::_exit(127);
  }
  return pid;
}

// The exit status of a raw waitpid status, or 128 + the signal that ended the process (the
// shell's convention).
inline int exit_status_of_raw(int raw) {
  return WIFEXITED(raw) ? WEXITSTATUS(raw) : 128 + (WIFSIGNALED(raw) ? WTERMSIG(raw) : 0);
}

// Waits for the child; its exit status or 128 + signal.
inline int wait_child(pid_t pid) {
  int raw = 0;
  ::waitpid(pid, &raw, 0);
  return exit_status_of_raw(raw);
}

}  // namespace mresim::testing
