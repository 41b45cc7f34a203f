// Runs the built `mresim` executables as a user would, in a fresh directory.
// MRESIM_CLI_PATH is the real command; MRESIM_TESTBED_PATH is the same command with the
// test-only run type "test_dummy" (tests/support/dummy_run_type.cpp) linked in.

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <mresim/core/version.hpp>
#include <nlohmann/json.hpp>
#include <regex>
#include <string>

#include "../support/child_process.hpp"
#include "../support/hdf5_read.hpp"
#include "../support/temp_dir.hpp"

namespace {

namespace fs = std::filesystem;
using mresim::testing::CommandResult;
using mresim::testing::Hdf5Reader;
using mresim::testing::listing;
using mresim::testing::read_text;
using mresim::testing::TempDir;
using mresim::testing::write_text;

// Runs `program args` with `env` assignments prepended, in `dir`; captures stdout and stderr.
CommandResult run_shell_in(const fs::path& dir, const std::string& program, const std::string& args,
                           const std::string& env = {}) {
  const fs::path out = dir / ".stdout";
  const fs::path err = dir / ".stderr";
  const std::string command = "cd '" + dir.string() + "' && " + env + " '" + program + "' " + args +
                              " >'" + out.string() + "' 2>'" + err.string() + "' </dev/null";
  const int raw = std::system(command.c_str());
  CommandResult result;
  result.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  result.out = read_text(out);
  result.err = read_text(err);
  fs::remove(out);
  fs::remove(err);
  return result;
}

CommandResult mresim(const fs::path& dir, const std::string& args, const std::string& env = {}) {
  return run_shell_in(dir, MRESIM_CLI_PATH, args, env);
}
CommandResult testbed(const fs::path& dir, const std::string& args, const std::string& env = {}) {
  return run_shell_in(dir, MRESIM_TESTBED_PATH, args, env);
}

const char* const kDummyRun =
    "[run]\n"
    "type = \"test_dummy\"\n"
    "title = \"CLI test\"\n"
    "[dummy]\n"
    "steps = 3\n"
    "scale = 0.5\n";

// The fake plot scripts below need only a Python interpreter, not matplotlib.
bool have_python3() { return std::system("python3 -c '' >/dev/null 2>&1") == 0; }

TEST(Cli, HelpDocumentsEveryCommandAndOption) {
  const TempDir dir;
  const CommandResult top = mresim(dir.path(), "--help");
  EXPECT_EQ(top.status, 0);
  for (const char* word : {"run", "info", "plot", "types", "--version"}) {
    EXPECT_NE(top.out.find(word), std::string::npos) << word;
  }
  const CommandResult run = mresim(dir.path(), "run --help");
  EXPECT_EQ(run.status, 0);
  for (const char* word : {"FILE", "--out", "--threads", "--no-plot", "Run types"}) {
    EXPECT_NE(run.out.find(word), std::string::npos) << word;
  }
  const CommandResult info = mresim(dir.path(), "info --help");
  EXPECT_EQ(info.status, 0);
  EXPECT_NE(info.out.find("--json"), std::string::npos);
  const CommandResult plot = mresim(dir.path(), "plot --help");
  EXPECT_EQ(plot.status, 0);
  EXPECT_NE(plot.out.find("DIR"), std::string::npos);
}

TEST(Cli, PrintsItsVersion) {
  const TempDir dir;
  const CommandResult r = mresim(dir.path(), "--version");
  EXPECT_EQ(r.status, 0);
  EXPECT_EQ(r.out, std::string("mresim ") + mresim::kVersion + "\n");
}

TEST(Cli, CommandLineMistakesExitWithStatus2) {
  const TempDir dir;
  const CommandResult none = mresim(dir.path(), "");
  EXPECT_EQ(none.status, 2);
  EXPECT_NE(none.err.find("mresim: error: "), std::string::npos);
  EXPECT_EQ(mresim(dir.path(), "run").status, 2);
  EXPECT_EQ(mresim(dir.path(), "run x.toml --bogus").status, 2);
  EXPECT_EQ(mresim(dir.path(), "run x.toml --threads -1").status, 2);
  EXPECT_EQ(mresim(dir.path(), "frobnicate").status, 2);
}

TEST(Cli, TypesListsTheRegisteredRunTypes) {
  const TempDir dir;
  EXPECT_EQ(mresim(dir.path(), "types").status, 0);
  const CommandResult r = testbed(dir.path(), "types");
  EXPECT_EQ(r.status, 0);
  EXPECT_TRUE(std::regex_search(r.out, std::regex(R"((^|\n)  test_dummy +Test-only run type\n)")))
      << r.out;
}

TEST(Cli, AnInvalidRunFileExitsWith2AndWritesNothing) {
  const TempDir dir;
  write_text(dir / "bad.toml", "[run]\ntype = \"no_such_type\"\n");
  const CommandResult r = testbed(dir.path(), "run bad.toml");
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.err.rfind("mresim: error: run.type = \"no_such_type\": ", 0), 0U) << r.err;
  EXPECT_EQ(listing(dir.path()), std::vector<std::string>{"bad.toml"});
}

TEST(Cli, MissingAndMalformedFilesExitWith2) {
  const TempDir dir;
  const CommandResult missing = mresim(dir.path(), "run absent.toml");
  EXPECT_EQ(missing.status, 2);
  EXPECT_EQ(missing.err,
            "mresim: error: cannot read run file 'absent.toml': No such file or directory\n");
  write_text(dir / "broken.toml", "[run\n");
  const CommandResult broken = mresim(dir.path(), "info broken.toml");
  EXPECT_EQ(broken.status, 2);
  EXPECT_EQ(broken.err.rfind("mresim: error: broken.toml:1:", 0), 0U) << broken.err;
  EXPECT_NE(broken.err.find("TOML syntax error"), std::string::npos);
  EXPECT_EQ(listing(dir.path()), std::vector<std::string>{"broken.toml"});
}

TEST(Cli, RunWritesACompleteRunDirectory) {
  const TempDir dir;
  write_text(dir / "demo.toml", kDummyRun);
  const CommandResult r = testbed(dir.path(), "run demo.toml --no-plot");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.out, "mresim: results written to demo\n");
  EXPECT_NE(r.err.find("test_dummy: done 3/3"), std::string::npos) << r.err;
  // The default output directory is named after the run file; no staging directory remains.
  EXPECT_EQ(listing(dir.path()), (std::vector<std::string>{"demo", "demo.toml"}));
  EXPECT_EQ(listing(dir / "demo"),
            (std::vector<std::string>{".mresim-manifest", "results.h5", "summary.csv"}));

  const Hdf5Reader h5(dir / "demo" / "results.h5");
  EXPECT_EQ(h5.string_attribute("/", "run_type"), "test_dummy");
  EXPECT_EQ(h5.string_attribute("/", "input_toml"), kDummyRun);
  EXPECT_EQ(h5.string_attribute("/", "input_file"), "demo.toml");
  EXPECT_EQ(h5.string_attribute("/", "mresim_version"), mresim::kVersion);
  EXPECT_EQ(h5.string_attribute("/", "title"), "CLI test");
  EXPECT_EQ(h5.doubles("/dummy/values"), (std::vector<double>{0.0, 0.5, 1.0}));
  EXPECT_EQ(read_text(dir / "demo" / "summary.csv"), "step,value_m\n0,0\n1,0.5\n2,1\n");
}

TEST(Cli, ThreadsComeFromTheCommandLineOrTheRunFile) {
  const TempDir dir;
  write_text(dir / "t.toml", std::string(kDummyRun) + "");
  write_text(dir / "t1.toml", "[run]\ntype = \"test_dummy\"\nthreads = 1\n[dummy]\nsteps = 1\n");
  ASSERT_EQ(testbed(dir.path(), "run t1.toml --no-plot").status, 0);
  EXPECT_EQ(Hdf5Reader(dir / "t1" / "results.h5")
                .scalar_attribute<std::int64_t>("/dummy", "threads", H5T_NATIVE_INT64),
            1);
  ASSERT_EQ(testbed(dir.path(), "run t1.toml --threads 2 --out t2 --no-plot").status, 0);
  const Hdf5Reader h5(dir / "t2" / "results.h5");
  EXPECT_EQ(h5.scalar_attribute<std::int64_t>("/dummy", "threads", H5T_NATIVE_INT64), 2);
  EXPECT_EQ(h5.scalar_attribute<std::int64_t>("/", "threads", H5T_NATIVE_INT64), 2);
}

TEST(Cli, AFailingRunExitsWith1AndLeavesNothing) {
  const TempDir dir;
  write_text(dir / "fail.toml", "[run]\ntype = \"test_dummy\"\n[dummy]\nsteps = 5\nfail_at = 2\n");
  const CommandResult r = testbed(dir.path(), "run fail.toml --no-plot");
  EXPECT_EQ(r.status, 1);
  // The progress lines of the steps before (stderr is no terminal), then the error.
  const std::string error = "mresim: error: dummy failure at step 2\n";
  ASSERT_GE(r.err.size(), error.size()) << r.err;
  EXPECT_EQ(r.err.substr(r.err.size() - error.size()), error) << r.err;
  EXPECT_EQ(listing(dir.path()), std::vector<std::string>{"fail.toml"});
}

TEST(Cli, UnknownKeysAreRejectedBeforeAnythingIsWritten) {
  const TempDir dir;
  write_text(dir / "typo.toml", "[run]\ntype = \"test_dummy\"\n[dummy]\nsteps = 2\nscael = 1\n");
  const CommandResult r = testbed(dir.path(), "run typo.toml --out results");
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.err,
            "mresim: error: unknown key 'dummy.scael' in [dummy]; allowed keys: fail_at, nan_at, "
            "own_safe_points, scale, signal_after_last_step, step_seconds, steps\n");
  EXPECT_EQ(listing(dir.path()), std::vector<std::string>{"typo.toml"});
}

TEST(Cli, RefusesToOverwriteADirectoryThatIsNotARun) {
  const TempDir dir;
  write_text(dir / "demo.toml", kDummyRun);
  fs::create_directories(dir / "data");
  write_text(dir / "data" / "keep.txt", "precious");
  const CommandResult r = testbed(dir.path(), "run demo.toml --out data --no-plot");
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.err,
            "mresim: error: output directory 'data' exists and was not written by mresim (it has "
            "no .mresim-manifest and holds 'keep.txt'); choose another --out, or add --force to "
            "move it aside (it is renamed, never deleted)\n");
  EXPECT_EQ(listing(dir / "data"), std::vector<std::string>{"keep.txt"});
  EXPECT_EQ(listing(dir.path()), (std::vector<std::string>{"data", "demo.toml"}));
}

TEST(Cli, ReplacesAnEarlierRun) {
  const TempDir dir;
  write_text(dir / "demo.toml", kDummyRun);
  ASSERT_EQ(testbed(dir.path(), "run demo.toml --out out/a --no-plot").status, 0);
  write_text(dir / "demo.toml", "[run]\ntype = \"test_dummy\"\n[dummy]\nsteps = 1\n");
  ASSERT_EQ(testbed(dir.path(), "run demo.toml --out out/a --no-plot").status, 0);
  EXPECT_EQ(Hdf5Reader(dir / "out" / "a" / "results.h5").doubles("/dummy/values"),
            std::vector<double>{0.0});
  EXPECT_EQ(listing(dir / "out"), std::vector<std::string>{"a"});
}

TEST(Cli, InfoDescribesTheRunAsTextOrJson) {
  const TempDir dir;
  write_text(dir / "demo.toml", kDummyRun);
  const CommandResult text = testbed(dir.path(), "info demo.toml");
  ASSERT_EQ(text.status, 0) << text.err;
  EXPECT_EQ(text.out,
            "[run]\n"
            "  file     demo.toml\n"
            "  type     test_dummy\n"
            "  title    CLI test\n"
            "  threads  0  0 = all cores\n"
            "\n"
            "[dummy]\n"
            "  steps         3\n"
            "  scale         0.5 m  length of one step\n"
            "  total_length  1.5 m\n");
  const CommandResult json = testbed(dir.path(), "info demo.toml --json");
  ASSERT_EQ(json.status, 0) << json.err;
  const auto parsed = nlohmann::json::parse(json.out);
  EXPECT_EQ(parsed["dummy"]["total_length"]["value"].get<double>(), 1.5);
  EXPECT_EQ(parsed["run"]["type"]["value"], "test_dummy");
  EXPECT_EQ(listing(dir.path()), std::vector<std::string>{"demo.toml"});
}

// A stand-in for python/mresim_plot.py that records its argument and exits with `status`.
void write_fake_plot_script(const fs::path& python_dir, int status) {
  fs::create_directories(python_dir);
  write_text(python_dir / "mresim_plot.py",
             fmt::format("import os, sys\n"
                         "figures = os.path.join(sys.argv[1], 'figures')\n"
                         "os.makedirs(figures, exist_ok=True)\n"
                         "open(os.path.join(figures, 'backend.txt'), 'w')"
                         ".write(os.environ.get('MPLBACKEND', ''))\n"
                         "sys.exit({})\n",
                         status));
}

TEST(Cli, RunDrawsFiguresWithThePlotScript) {
  if (!have_python3()) GTEST_SKIP() << "python3 not found";
  const TempDir dir;
  write_fake_plot_script(dir / "py", 0);
  write_text(dir / "demo.toml", kDummyRun);
  const std::string env = "MRESIM_PYTHON_DIR='" + (dir / "py").string() + "'";
  const CommandResult r =
      testbed(dir.path(), "run demo.toml",
              "env -u MPLBACKEND MRESIM_PYTHON_DIR='" + (dir / "py").string() + "'");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(read_text(dir / "demo" / "figures" / "backend.txt"), "Agg");
  // `mresim plot` redraws and propagates the script's status.
  write_fake_plot_script(dir / "py", 7);
  EXPECT_EQ(mresim(dir.path(), "plot demo", env).status, 7);
}

// `mresim plot DIR` passes the view options on to the script, one value per option as given
// (mresim_plot.py checks them); DIR may come before or after them.
TEST(Cli, PlotPassesTheViewOptionsToTheScript) {
  if (!have_python3()) GTEST_SKIP() << "python3 not found";
  const TempDir dir;
  fs::create_directories(dir / "py");
  write_text(dir / "py" / "mresim_plot.py",
             "import sys\n"
             "open(sys.argv[1] + '/args.txt', 'w').write('|'.join(sys.argv[2:]))\n");
  write_text(dir / "demo.toml", kDummyRun);
  ASSERT_EQ(testbed(dir.path(), "run demo.toml --no-plot").status, 0);
  const std::string env = "MRESIM_PYTHON_DIR='" + (dir / "py").string() + "'";
  const CommandResult r = mresim(dir.path(),
                                 "plot demo --step 0,3 --plane y@1 --plane=z=mid --particle 1 "
                                 "--field-map eps_xz --step last --animate",
                                 env);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(read_text(dir / "demo" / "args.txt"),
            "--step|0,3|--step|last|--plane|y@1|--plane|z=mid|--particle|1|--field-map|eps_xz|"
            "--animate");
  const CommandResult before = mresim(dir.path(), "plot --step 2 --plane y=4.5e-6 demo", env);
  ASSERT_EQ(before.status, 0) << before.err;
  EXPECT_EQ(read_text(dir / "demo" / "args.txt"), "--step|2|--plane|y=4.5e-6");
  const CommandResult none = mresim(dir.path(), "plot demo", env);
  ASSERT_EQ(none.status, 0) << none.err;
  EXPECT_EQ(read_text(dir / "demo" / "args.txt"), "");
  const CommandResult help = mresim(dir.path(), "plot --help");
  for (const char* word : {"--step", "--plane", "--particle", "--field-map", "--animate"}) {
    EXPECT_NE(help.out.find(word), std::string::npos) << word;
  }
}

// A 3D run with solver.method = "newton" starts MPI, whose singleton start forks a helper
// process; started after results.h5 was open, the helper kept HDF5's lock on it and the plot
// script could not read it. The fake script takes the shared lock h5py would.
TEST(Cli, NewtonRunLeavesTheResultsReadableToThePlotScript) {
  if (!have_python3()) GTEST_SKIP() << "python3 not found";
  const TempDir dir;
  fs::create_directories(dir / "py");
  write_text(dir / "py" / "mresim_plot.py",
             "import fcntl, os, sys\n"
             "fd = os.open(os.path.join(sys.argv[1], 'results.h5'), os.O_RDONLY)\n"
             "try:\n"
             "    fcntl.flock(fd, fcntl.LOCK_SH | fcntl.LOCK_NB)\n"
             "except OSError:\n"
             "    sys.exit(9)\n"
             "sys.exit(0)\n");
  write_text(dir / "newton.toml",
             "[run]\ntype = \"mess_hysteresis\"\n"
             "[model]\nprofile = \"physical\"\ndiscretization_order = 1\n"
             "[particles]\nplacement = \"chain\"\ncount = 2\nseparation = 7e-6\naxis = \"z\"\n"
             "[box]\nsize = [9e-6, 9e-6, 17e-6]\n"
             "[field]\nmagnitudes = [0.02]\nsequence = \"up\"\n"
             "[solver]\nmethod = \"newton\"\n");
  const CommandResult r =
      mresim(dir.path(), "run newton.toml", "MRESIM_PYTHON_DIR='" + (dir / "py").string() + "'");
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(fs::is_regular_file(dir / "newton" / "results.h5"));
}

TEST(Cli, AFailedPlotAfterASuccessfulRunExitsWith3) {
  if (!have_python3()) GTEST_SKIP() << "python3 not found";
  const TempDir dir;
  write_fake_plot_script(dir / "py", 1);
  write_text(dir / "demo.toml", kDummyRun);
  const CommandResult r =
      testbed(dir.path(), "run demo.toml", "MRESIM_PYTHON_DIR='" + (dir / "py").string() + "'");
  EXPECT_EQ(r.status, 3);
  EXPECT_NE(r.err.find("retry with 'mresim plot demo'"), std::string::npos) << r.err;
  EXPECT_TRUE(fs::is_regular_file(dir / "demo" / "results.h5"));
}

TEST(Cli, PlotExplainsWhatIsMissing) {
  const TempDir dir;
  const CommandResult not_run = mresim(dir.path(), "plot .");
  EXPECT_EQ(not_run.status, 2);
  EXPECT_EQ(not_run.err,
            "mresim: error: '.' is not an mresim run directory (no results.h5 in it)\n");

  fs::create_directories(dir / "run");
  write_text(dir / "run" / "results.h5", "");
  const CommandResult no_script =
      mresim(dir.path(), "plot run", "MRESIM_PYTHON_DIR='" + (dir / "nowhere").string() + "'");
  EXPECT_EQ(no_script.status, 1);
  EXPECT_NE(no_script.err.find("mresim_plot.py' not found; set MRESIM_PYTHON_DIR"),
            std::string::npos)
      << no_script.err;

  // A missing interpreter, or one without matplotlib.
  write_fake_plot_script(dir / "py", 0);
  const std::string py_dir = "MRESIM_PYTHON_DIR='" + (dir / "py").string() + "'";
  const CommandResult no_python =
      mresim(dir.path(), "plot run", "MRESIM_PYTHON=/nonexistent/python3 " + py_dir);
  EXPECT_EQ(no_python.status, 127);
  EXPECT_NE(no_python.err.find("/nonexistent/python3 was not found; install with: apt-get install"),
            std::string::npos)
      << no_python.err;
  write_text(dir / "fake_python", "#!/bin/sh\nexit 1\n");
  fs::permissions(dir / "fake_python", fs::perms::owner_all);
  const CommandResult no_matplotlib = mresim(
      dir.path(), "plot run", "MRESIM_PYTHON='" + (dir / "fake_python").string() + "' " + py_dir);
  EXPECT_EQ(no_matplotlib.status, 1);
  EXPECT_NE(no_matplotlib.err.find("cannot import matplotlib, numpy and h5py; install with: "
                                   "apt-get install python3 python3-matplotlib python3-numpy "
                                   "python3-h5py (or set MRESIM_PYTHON"),
            std::string::npos)
      << no_matplotlib.err;
}

TEST(Cli, PlotFallsBackToTheSystemPythonWhenPathHasOneWithoutMatplotlib) {
  if (std::system("/usr/bin/python3 -c 'import matplotlib, numpy, h5py' >/dev/null 2>&1") != 0) {
    GTEST_SKIP() << "/usr/bin/python3 lacks matplotlib, numpy or h5py";
  }
  const TempDir dir;
  fs::create_directories(dir / "run");
  write_text(dir / "run" / "results.h5", "");
  write_fake_plot_script(dir / "py", 0);
  // A python3 first on PATH that can import nothing, as a bare virtualenv would; it complains
  // as Python does.
  fs::create_directories(dir / "bin");
  write_text(dir / "bin" / "python3",
             "#!/bin/sh\necho \"ModuleNotFoundError: No module named 'matplotlib'\" >&2\nexit 1\n");
  fs::permissions(dir / "bin" / "python3", fs::perms::owner_all);
  const CommandResult r =
      mresim(dir.path(), "plot run",
             "env -u MRESIM_PYTHON PATH='" + (dir / "bin").string() +
                 ":/usr/bin:/bin' MRESIM_PYTHON_DIR='" + (dir / "py").string() + "'");
  EXPECT_EQ(r.status, 0) << r.err;
  // Some interpreter works, so nothing is said about the one that does not.
  EXPECT_EQ(r.err.find("No module named"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("error"), std::string::npos) << r.err;
  EXPECT_TRUE(fs::exists(dir / "run" / "figures" / "backend.txt"));
}

}  // namespace
