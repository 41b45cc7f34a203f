// `mpirun -np 2 mresim run FILE` (docs/mpi.md): a 3D run whose relaxations split their
// evaluations over two processes gives the results of a single process within the issue's
// agreement (1 nm in particle centres, 1e-6 in M/Ms, 1e-6 relative in energy density, the same
// convergence), rank 0 writes the run directory alone, what cannot be split yet is refused
// before anything is written, and a run stopped by SIGTERM resumes over two processes.

#include <gtest/gtest.h>
#include <signal.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "../support/child_process.hpp"
#include "../support/hdf5_read.hpp"
#include "../support/temp_dir.hpp"

namespace {

namespace fs = std::filesystem;
using mresim::testing::Hdf5Reader;
using mresim::testing::read_text;
using mresim::testing::TempDir;

struct Result {
  int status = -1;
  std::string err;
};

// `mpirun -np <processes> mresim <args>` in `dir` (processes 0: mresim alone).
Result run(const fs::path& dir, int processes, std::vector<std::string> args) {
  fs::path program = MRESIM_CLI_PATH;
  if (processes > 0) {
    args.insert(args.begin(), {"--allow-run-as-root", "--oversubscribe", "-np",
                               std::to_string(processes), MRESIM_CLI_PATH});
    program = MRESIM_MPIEXEC;
  }
  const pid_t pid = mresim::testing::start_child(program, args, dir, ".stdout", ".stderr");
  Result r;
  r.status = mresim::testing::wait_child(pid);
  r.err = read_text(dir / ".stderr");
  return r;
}

bool have_mpirun() {
  const fs::path mpirun = MRESIM_MPIEXEC;  // CMake's MPIEXEC_EXECUTABLE
  // Copy-in/copy-out shared memory between the processes: containers often forbid the
  // cross-process copies (CMA) that OpenMPI's shared-memory transport uses by default.
  ::setenv("OMPI_MCA_btl_vader_single_copy_mechanism", "none", 1);
  return !mpirun.empty() && fs::exists(mpirun);
}

const std::string kSmallPairExample =
    std::string(MRESIM_SOURCE_DIR) +
    "/examples/chapter4/small/fig4_11_pair_large_box_S6_5um_small.toml";

// The small Fig. 4.11 pair (6,144 nodes, seed profile) through a shorter loop:
// 0 -> 20 -> -20 -> 20 mT in 20 mT steps, one thread per process.
std::vector<std::string> run_args(const std::string& out) {
  return {"run", kSmallPairExample, "--out",          out,     "--no-plot",    "-j",
          "1",   "--set",           "field.max=0.02", "--set", "field.steps=1"};
}

std::set<std::string> files_in(const fs::path& dir) {
  std::set<std::string> names;
  for (const auto& entry : fs::recursive_directory_iterator(dir)) {
    names.insert(fs::relative(entry.path(), dir).string());
  }
  return names;
}

double max_difference(const std::vector<double>& a, const std::vector<double>& b) {
  double m = 0.0;
  for (std::size_t i = 0; i < std::min(a.size(), b.size()); ++i) {
    m = std::max(m, std::abs(a[i] - b[i]));
  }
  return m;
}

}  // namespace

TEST(MpiRunCli, TwoProcessesGiveTheResultsOfOne) {
  if (!have_mpirun()) GTEST_SKIP() << "no MPI launcher (mpirun) found";
  const TempDir dir;
  const Result one = run(dir.path(), 0, run_args("one"));
  ASSERT_EQ(one.status, 0) << one.err;
  const Result two = run(dir.path(), 2, run_args("two"));
  ASSERT_EQ(two.status, 0) << two.err;

  // Rank 0 wrote the directory; nothing else appeared.
  EXPECT_EQ(files_in(dir / "two"), files_in(dir / "one"));
  std::set<std::string> top;
  for (const auto& entry : fs::directory_iterator(dir.path())) {
    top.insert(entry.path().filename().string());
  }
  EXPECT_EQ(top, (std::set<std::string>{".stderr", ".stdout", "one", "two"}));

  const Hdf5Reader a(dir / "one" / "results.h5");
  const Hdf5Reader b(dir / "two" / "results.h5");
  EXPECT_EQ(a.scalar_attribute<std::int64_t>("/", "mpi_processes", H5T_NATIVE_INT64), 1);
  EXPECT_EQ(b.scalar_attribute<std::int64_t>("/", "mpi_processes", H5T_NATIVE_INT64), 2);
  EXPECT_EQ(a.ints("steps/valid"), b.ints("steps/valid"));
  EXPECT_EQ(a.ints("observables/converged/value"), b.ints("observables/converged/value"));
  const std::vector<double> centres = a.doubles("steps/centres");
  ASSERT_EQ(centres.size(), b.doubles("steps/centres").size());
  EXPECT_GT(centres.size(), 6U);
  EXPECT_LE(max_difference(centres, b.doubles("steps/centres")), 1e-9);  // 1 nm
  const double ms = 1.6e6;  // A/m, the example's saturation magnetization
  EXPECT_LE(max_difference(a.doubles("steps/magnetization"), b.doubles("steps/magnetization")),
            1e-6 * ms);
  const std::vector<double> ea = a.doubles("steps/energy_density");
  const std::vector<double> eb = b.doubles("steps/energy_density");
  ASSERT_EQ(ea.size(), eb.size());
  for (std::size_t i = 0; i < ea.size(); ++i) {
    EXPECT_LE(std::abs(ea[i] - eb[i]), 1e-6 * std::abs(ea[i])) << "step " << i;
  }
}

TEST(MpiRunCli, RefusesWhatCannotSplitOverProcesses) {
  if (!have_mpirun()) GTEST_SKIP() << "no MPI launcher (mpirun) found";
  const TempDir dir;
  std::vector<std::string> newton = run_args("newton");
  newton.insert(newton.end(), {"--set", "solver.method=newton"});
  const Result r = run(dir.path(), 2, newton);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("solver.method = \"newton\""), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "newton"));

  // A rerun whose steps before --step must be computed again (their states not kept) with the
  // run's own method, which cannot split: refused before anything is written.
  // (0 and 20 mT only: Newton's run is the slow part of this test.)
  std::vector<std::string> newton_run = run_args("newton_run");
  newton_run.insert(newton_run.end(),
                    {"--set", "field.sequence=up", "--set", "solver.method=newton", "--set",
                     "output.node_positions=false"});
  ASSERT_EQ(run(dir.path(), 0, newton_run).status, 0);
  const std::set<std::string> before = files_in(dir / "newton_run");
  const Result rerun =
      run(dir.path(), 2,
          {"rerun", "newton_run", "--step", "1", "--no-plot", "--set", "solver.method=minimiser"});
  EXPECT_EQ(rerun.status, 2) << rerun.err;
  EXPECT_NE(rerun.err.find("--step 1: the state before it was not kept"), std::string::npos)
      << rerun.err;
  EXPECT_NE(rerun.err.find("solver.method = \"newton\""), std::string::npos) << rerun.err;
  EXPECT_EQ(files_in(dir / "newton_run"), before);

  const std::string pair =
      std::string(MRESIM_SOURCE_DIR) + "/examples/fig2_2_single_spring_axial.toml";
  const Result two_dipole = run(dir.path(), 2, {"run", pair, "--out", "pair", "--no-plot"});
  EXPECT_NE(two_dipole.status, 0);
  EXPECT_NE(two_dipole.err.find("cannot split a run over MPI processes"), std::string::npos)
      << two_dipole.err;
  EXPECT_FALSE(fs::exists(dir / "pair"));
}

// Every result `mresim extend` and `rerun` write per step, between a single-process and a
// two-process command: the relaxations' states bitwise (the split evaluation's gradient is the
// single process's), the energies to rounding (their node sums are added per process).
void expect_same_steps(const fs::path& one, const fs::path& two) {
  const Hdf5Reader a(one / "results.h5");
  const Hdf5Reader b(two / "results.h5");
  EXPECT_EQ(b.scalar_attribute<std::int64_t>("/", "mpi_processes", H5T_NATIVE_INT64), 2);
  for (const char* path : {"/steps/centres", "/steps/magnetization", "/steps/solver/max_force"}) {
    EXPECT_EQ(a.doubles(path), b.doubles(path)) << path;
  }
  EXPECT_EQ(a.ints("/steps/solver/iterations"), b.ints("/steps/solver/iterations"));
  EXPECT_EQ(a.ints("/steps/valid"), b.ints("/steps/valid"));
  const std::vector<double> ea = a.doubles("/steps/energies/total");
  const std::vector<double> eb = b.doubles("/steps/energies/total");
  ASSERT_EQ(ea.size(), eb.size());
  for (std::size_t i = 0; i < ea.size(); ++i) {
    EXPECT_LE(std::abs(ea[i] - eb[i]), 1e-12 * std::abs(ea[i])) << "step " << i;
  }
  // The history entry that records the command, the same in both.
  EXPECT_EQ(a.ints("/history/0/replaced_steps"), b.ints("/history/0/replaced_steps"));
  EXPECT_EQ(files_in(one), files_in(two));
}

// `mresim <command> <one> <args>` by one process and `mpirun -np 2 mresim <command> <two>
// <args>`, both succeeding, then expect_same_steps on the two directories. The two-process
// run's stderr stays in dir/.stderr.
void expect_one_and_two_processes_agree(const fs::path& dir, const std::string& command,
                                        const std::string& one, const std::string& two,
                                        const std::vector<std::string>& args) {
  std::vector<std::string> single = {command, one};
  single.insert(single.end(), args.begin(), args.end());
  std::vector<std::string> split = {command, two};
  split.insert(split.end(), args.begin(), args.end());
  const Result r1 = run(dir, 0, single);
  ASSERT_EQ(r1.status, 0) << r1.err;
  const Result r2 = run(dir, 2, split);
  ASSERT_EQ(r2.status, 0) << r2.err;
  expect_same_steps(dir / one, dir / two);
}

// `mpirun -np 2 mresim extend` and `rerun` (docs/mpi.md): the same steps as one process.
TEST(MpiRunCli, ExtendAndRerunOverProcessesGiveTheResultsOfOne) {
  if (!have_mpirun()) GTEST_SKIP() << "no MPI launcher (mpirun) found";
  const TempDir dir;
  ASSERT_EQ(run(dir.path(), 0, run_args("base")).status, 0);
  for (const char* copy : {"extend_one", "extend_two", "rerun_one", "rerun_two"}) {
    fs::copy(dir / "base", dir / copy, fs::copy_options::recursive);
  }
  // The loop to 40 mT in 20 mT steps: five steps added to the six computed.
  expect_one_and_two_processes_agree(
      dir.path(), "extend", "extend_one", "extend_two",
      {"--no-plot", "-j", "1", "--set", "field.max=0.04", "--set", "field.steps=2"});
  EXPECT_EQ(Hdf5Reader(dir / "extend_two" / "results.h5").doubles("/steps/centres").size(),
            11U * 2U * 3U);
  // Step 3 (-20 mT after 0 mT; the steps at 0 mT start from the field secant, which returns
  // them to the lattice, already their equilibrium) relaxed again with a 100 times tighter
  // force tolerance.
  expect_one_and_two_processes_agree(
      dir.path(), "rerun", "rerun_one", "rerun_two",
      {"--step", "3", "--no-plot", "-j", "1", "--set", "solver.minimiser.force_tolerance=1e-8"});
  // The rerun did relax step 3 again (tighter: a smaller largest force than the run's).
  EXPECT_LT(Hdf5Reader(dir / "rerun_two" / "results.h5").doubles("/steps/solver/max_force")[3],
            Hdf5Reader(dir / "base" / "results.h5").doubles("/steps/solver/max_force")[3]);
}

// A rerun of a run that kept no positions computes the steps before --step again first; over
// two processes both relaxations split, to the single process's results.
TEST(MpiRunCli, RerunThatComputesEarlierStepsAgainSplitsThemToo) {
  if (!have_mpirun()) GTEST_SKIP() << "no MPI launcher (mpirun) found";
  const TempDir dir;
  std::vector<std::string> args = run_args("base");
  args.insert(args.end(), {"--set", "output.node_positions=false"});
  ASSERT_EQ(run(dir.path(), 0, args).status, 0);
  fs::copy(dir / "base", dir / "one", fs::copy_options::recursive);
  fs::copy(dir / "base", dir / "two", fs::copy_options::recursive);
  expect_one_and_two_processes_agree(
      dir.path(), "rerun", "one", "two",
      {"--step", "3", "--no-plot", "-j", "1", "--set", "solver.minimiser.force_tolerance=1e-8"});
  const std::string err = read_text(dir / ".stderr");  // the two-process run's
  EXPECT_NE(err.find("steps 0 to 2 are computed again first"), std::string::npos) << err;
}

// The processes of mpirun, i.e. its children (the launcher starts them directly on this
// machine), from /proc.
std::vector<pid_t> children_of(pid_t parent) {
  std::vector<pid_t> children;
  for (const auto& entry : fs::directory_iterator("/proc")) {
    const std::string name = entry.path().filename().string();
    if (name.empty() || !std::all_of(name.begin(), name.end(), ::isdigit)) continue;
    // /proc/<pid>/stat: "pid (comm) state ppid ..."; comm may hold spaces, so parse after ')'.
    const std::string stat = read_text(entry.path() / "stat");
    const auto close = stat.rfind(')');
    if (close == std::string::npos) continue;
    std::istringstream rest(stat.substr(close + 1));
    std::string state;
    long ppid = 0;
    rest >> state >> ppid;
    if (ppid == parent) children.push_back(static_cast<pid_t>(std::stol(name)));
  }
  return children;
}

// The MPI rank of a process started by OpenMPI's mpirun (its environment names it), -1 if none.
int rank_of(pid_t pid) {
  std::string environment = read_text(fs::path("/proc") / std::to_string(pid) / "environ");
  std::replace(environment.begin(), environment.end(), '\0', '\n');
  std::istringstream lines(environment);
  const std::string key = "OMPI_COMM_WORLD_RANK=";
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind(key, 0) == 0) return std::stoi(line.substr(key.size()));
  }
  return -1;
}

// SIGTERM to one process of the job, the one that is not rank 0 (a scheduler signals every
// task, a user may signal one): both stop at the same step boundary, rank 0 names the signal
// it did not receive itself and writes the checkpoint; `mpirun -np 2 mresim resume` continues
// it, the other process reading the same checkpoint, to results bitwise those of an
// uninterrupted two-process run. (A signal to mpirun itself reaches the processes too, but
// OpenMPI kills them a second later, before a long step ends: docs/cli.md.)
TEST(MpiRunCli, StoppedRunResumesOverProcessesToTheSameResults) {
  if (!have_mpirun()) GTEST_SKIP() << "no MPI launcher (mpirun) found";
  const TempDir dir;
  // The whole small loop (11 steps, several seconds): long enough to stop in the middle.
  const std::vector<std::string> args = {
      "run", kSmallPairExample, "--out", "full", "--no-plot", "-j", "1"};
  ASSERT_EQ(run(dir.path(), 2, args).status, 0);

  std::vector<std::string> stopped = {"--allow-run-as-root",
                                      "--oversubscribe",
                                      "-np",
                                      "2",
                                      MRESIM_CLI_PATH,
                                      "run",
                                      kSmallPairExample,
                                      "--out",
                                      "stopped",
                                      "--no-plot",
                                      "-j",
                                      "1"};
  const pid_t pid =
      mresim::testing::start_child(MRESIM_MPIEXEC, stopped, dir.path(), ".stdout", ".stderr-bg");
  // Once the run is under way (its second step reported; the third, the snap into contact,
  // takes seconds).
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (read_text(dir / ".stderr-bg").find("step 2/11") == std::string::npos &&
         std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  const std::vector<pid_t> processes = children_of(pid);
  ASSERT_EQ(processes.size(), 2U);
  std::vector<int> ranks;
  for (const pid_t p : processes) ranks.push_back(rank_of(p));
  std::sort(ranks.begin(), ranks.end());
  ASSERT_EQ(ranks, (std::vector<int>{0, 1}));
  for (const pid_t p : processes) {
    if (rank_of(p) == 1) ::kill(p, SIGTERM);
  }
  EXPECT_NE(mresim::testing::wait_child(pid), 0);
  const std::string err = read_text(dir / ".stderr-bg");
  ASSERT_NE(err.find("mresim: interrupted by SIGTERM after step "), std::string::npos) << err;
  ASSERT_FALSE(fs::exists(dir / "stopped"));

  const Result resumed = run(dir.path(), 2, {"resume", "stopped", "--no-plot", "-j", "1"});
  ASSERT_EQ(resumed.status, 0) << resumed.err;
  EXPECT_NE(resumed.err.find("resuming at step"), std::string::npos) << resumed.err;
  const Hdf5Reader a(dir / "full" / "results.h5");
  const Hdf5Reader b(dir / "stopped" / "results.h5");
  for (const char* path : {"/steps/centres", "/steps/magnetization", "/steps/energies/total",
                           "/steps/energies/springs", "/steps/solver/max_force"}) {
    EXPECT_EQ(a.doubles(path), b.doubles(path)) << path;
  }
  EXPECT_EQ(a.ints("/steps/solver/iterations"), b.ints("/steps/solver/iterations"));
}
