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

#include "temp_dir.hpp"

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

// What a finished program left: its exit status (or 128 + signal), stdout and stderr.
struct CommandResult {
  int status = -1;
  std::string out;
  std::string err;
};

// Runs `program args...` in `dir` and waits for it. stdout and stderr go to the files
// .stdout<capture_suffix> and .stderr<capture_suffix> in `dir`, read back and removed.
inline CommandResult run_program(const std::filesystem::path& program,
                                 const std::filesystem::path& dir,
                                 const std::vector<std::string>& args,
                                 const std::string& capture_suffix = "") {
  const std::string out = ".stdout" + capture_suffix;
  const std::string err = ".stderr" + capture_suffix;
  const pid_t pid = start_child(program, args, dir, out, err);
  CommandResult r;
  r.status = wait_child(pid);
  r.out = read_text(dir / out);
  r.err = read_text(dir / err);
  std::filesystem::remove(dir / out);
  std::filesystem::remove(dir / err);
  return r;
}

}  // namespace mresim::testing
