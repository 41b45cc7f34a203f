#include "cli/plotting.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

extern char** environ;  // NOLINT: POSIX global, passed on to the child

namespace mresim::cli {

namespace {

constexpr const char* kInstallHint =
    "install with: apt-get install python3 python3-matplotlib python3-numpy python3-h5py";

struct ChildResult {
  bool started = false;
  int exit_status = 0;
};

// Runs a program found on PATH, with matplotlib's non-interactive backend unless the user chose
// one (figures are files; no display is needed or wanted). Quiet children have their output
// sent to /dev/null.
ChildResult spawn_and_wait(const std::vector<std::string>& args, bool quiet) {
  std::vector<char*> argv;
  argv.reserve(args.size() + 1);
  for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);

  std::vector<std::string> env_storage;
  for (char** e = environ; *e != nullptr; ++e) env_storage.emplace_back(*e);
  if (std::getenv("MPLBACKEND") == nullptr) env_storage.emplace_back("MPLBACKEND=Agg");
  std::vector<char*> envp;
  envp.reserve(env_storage.size() + 1);
  for (auto& e : env_storage) envp.push_back(e.data());
  envp.push_back(nullptr);

  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  if (quiet) {
    posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
    posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, "/dev/null", O_WRONLY, 0);
  }
  pid_t pid = 0;
  const int spawn_error = posix_spawnp(&pid, argv[0], &actions, nullptr, argv.data(), envp.data());
  posix_spawn_file_actions_destroy(&actions);
  if (spawn_error != 0) return {false, 127};

  int status = 0;
  while (waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR)
      throw std::runtime_error(fmt::format("waitpid failed: {}", std::strerror(errno)));
  }
  if (WIFEXITED(status)) return {true, WEXITSTATUS(status)};
  return {true, 128 + (WIFSIGNALED(status) ? WTERMSIG(status) : 0)};
}

}  // namespace

std::filesystem::path python_dir() {
  const char* from_env = std::getenv("MRESIM_PYTHON_DIR");
  if (from_env != nullptr && *from_env != '\0') return from_env;
  return MRESIM_PYTHON_DIR;
}

std::string python_interpreter() {
  const char* from_env = std::getenv("MRESIM_PYTHON");
  return from_env != nullptr && *from_env != '\0' ? from_env : "python3";
}

namespace {

// Debian's interpreter, the one python3-matplotlib & co. install into.
constexpr const char* kSystemPython = "/usr/bin/python3";

bool has_plot_modules(const std::string& python) {
  const ChildResult r = spawn_and_wait({python, "-c", "import matplotlib, numpy, h5py"}, true);
  return r.started && r.exit_status == 0;
}

}  // namespace

int draw_figures(const std::filesystem::path& run_dir) {
  const auto script = python_dir() / "mresim_plot.py";
  if (!std::filesystem::is_regular_file(script)) {
    throw std::runtime_error(fmt::format(
        "plot script '{}' not found; set MRESIM_PYTHON_DIR to the directory holding mresim_plot.py",
        script.string()));
  }
  const bool user_chose_python = std::getenv("MRESIM_PYTHON") != nullptr;
  const std::string python = python_interpreter();
  const ChildResult plot = spawn_and_wait({python, script.string(), run_dir.string()}, false);
  if (plot.started && plot.exit_status == 0) return 0;

  const bool modules_found = plot.started && has_plot_modules(python);
  if (!modules_found && !user_chose_python && python != kSystemPython &&
      std::filesystem::exists(kSystemPython) && has_plot_modules(kSystemPython)) {
    // A python3 earlier on PATH (pyenv, conda, a virtualenv) often lacks the Debian packages
    // the README installs; the system interpreter has them.
    std::fprintf(stderr, "mresim: note: %s lacks matplotlib, numpy or h5py; using %s\n",
                 python.c_str(), kSystemPython);
    return spawn_and_wait({kSystemPython, script.string(), run_dir.string()}, false).exit_status;
  }
  if (!plot.started) {
    std::fprintf(stderr, "mresim: error: %s was not found; %s\n", python.c_str(), kInstallHint);
  } else if (!modules_found) {
    // The commonest cause of a failed plot by far: say exactly what to install.
    std::fprintf(stderr,
                 "mresim: error: %s cannot import matplotlib, numpy and h5py; %s (or set "
                 "MRESIM_PYTHON to a Python interpreter that has them)\n",
                 python.c_str(), kInstallHint);
  }
  return plot.exit_status;
}

}  // namespace mresim::cli
