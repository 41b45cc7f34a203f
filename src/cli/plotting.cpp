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

#include "mresim/io/run_manifest.hpp"

extern char** environ;  // NOLINT: POSIX global, passed on to the child

namespace mresim::cli {

namespace {

constexpr const char* kInstallHint =
    "install with: apt-get install python3 python3-matplotlib python3-numpy python3-h5py";

struct ChildResult {
  bool started = false;
  int exit_status = 0;
};

// What of a child's output reaches mresim's stdout and stderr.
enum class ChildOutput { shown, errors_only, hidden };

// Runs a program found on PATH, with matplotlib's non-interactive backend unless the user chose
// one (figures are files; no display is needed or wanted). What the child's output does not
// show goes to /dev/null.
ChildResult spawn_and_wait(const std::vector<std::string>& args, ChildOutput shown) {
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
  if (shown != ChildOutput::shown) {
    posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
  }
  if (shown == ChildOutput::hidden) {
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

std::filesystem::path installed_python_dir() {
  // An installed mresim (cmake --install) lies in <prefix>/bin, its scripts in
  // <prefix>/share/mresim/python: found through the executable, wherever the prefix was moved.
  std::error_code ec;
  const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (ec) return {};
  const std::filesystem::path dir =
      exe.parent_path().parent_path() / MRESIM_INSTALL_PYTHON_SCRIPTS_DIR;
  return std::filesystem::is_regular_file(dir / "mresim_plot.py", ec) ? dir
                                                                      : std::filesystem::path();
}

std::filesystem::path python_dir() {
  const char* from_env = std::getenv("MRESIM_PYTHON_DIR");
  if (from_env != nullptr && *from_env != '\0') return from_env;
  if (auto installed = installed_python_dir(); !installed.empty()) return installed;
  return MRESIM_PYTHON_DIR;  // the source tree's, for the build tree's mresim
}

std::string python_interpreter() {
  const char* from_env = std::getenv("MRESIM_PYTHON");
  return from_env != nullptr && *from_env != '\0' ? from_env : "python3";
}

namespace {

// Debian's interpreter, the one python3-matplotlib & co. install into.
constexpr const char* kSystemPython = "/usr/bin/python3";

bool has_plot_modules(const std::string& python) {
  const ChildResult r =
      spawn_and_wait({python, "-c", "import matplotlib, numpy, h5py"}, ChildOutput::hidden);
  return r.started && r.exit_status == 0;
}

// The interpreter to draw with: the chosen one (MRESIM_PYTHON, else python3 on PATH) if it has
// the plotting modules; else Debian's, which the README's packages install into. A python3
// earlier on PATH (pyenv, conda, a virtualenv) often lacks them; that is no error as long as
// some interpreter works, so nothing is said then. Empty if none works, after the message, with
// `failure_status` set: 127 if the interpreter does not exist, 1 if it lacks the modules.
std::string plotting_interpreter(int& failure_status) {
  std::string python = python_interpreter();
  if (has_plot_modules(python)) return python;
  const bool user_chose_python = std::getenv("MRESIM_PYTHON") != nullptr;
  if (!user_chose_python && python != kSystemPython && std::filesystem::exists(kSystemPython) &&
      has_plot_modules(kSystemPython)) {
    return kSystemPython;
  }
  const ChildResult found = spawn_and_wait({python, "-c", "pass"}, ChildOutput::hidden);
  failure_status = found.started ? 1 : 127;
  if (!found.started) {
    std::fprintf(stderr, "mresim: error: %s was not found; %s\n", python.c_str(), kInstallHint);
  } else {
    // The commonest cause of a failed plot by far: say exactly what to install.
    std::fprintf(stderr,
                 "mresim: error: %s cannot import matplotlib, numpy and h5py; %s (or set "
                 "MRESIM_PYTHON to a Python interpreter that has them)\n",
                 python.c_str(), kInstallHint);
  }
  return "";
}

}  // namespace

int draw_figures(const std::filesystem::path& run_dir, const std::vector<std::string>& script_args,
                 bool quiet) {
  const auto script = python_dir() / "mresim_plot.py";
  if (!std::filesystem::is_regular_file(script)) {
    throw std::runtime_error(fmt::format(
        "plot script '{}' not found; set MRESIM_PYTHON_DIR to the directory holding mresim_plot.py",
        script.string()));
  }
  int failure_status = 0;
  const std::string python = plotting_interpreter(failure_status);
  if (python.empty()) return failure_status;
  const auto started = std::filesystem::file_time_type::clock::now();
  std::vector<std::string> args = {python, script.string(), run_dir.string()};
  args.insert(args.end(), script_args.begin(), script_args.end());
  const ChildResult plot =
      spawn_and_wait(args, quiet ? ChildOutput::errors_only : ChildOutput::shown);
  // The figures are mresim's files: list them in the run's manifest, so that a later run may
  // replace the directory. Only what this plot wrote, never a file the user put there.
  io::run_manifest::add_files_below(run_dir, "figures", started);
  return plot.started ? plot.exit_status : 127;
}

}  // namespace mresim::cli
