// `mresim sweep`, `mresim collect` (docs/sweeps.md): one run directory per point with its
// parameters recorded, finished points skipped when run again, a failed point reported but not
// fatal, --index running exactly one point, and a sweep over two MPI ranks collecting the same
// tables as one process. Each point is a coarse two-dipole loop (milliseconds).

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "../support/child_process.hpp"
#include "../support/hdf5_read.hpp"
#include "../support/temp_dir.hpp"

namespace {

namespace fs = std::filesystem;
using mresim::testing::CommandResult;
using mresim::testing::Hdf5Reader;
using mresim::testing::read_text;
using mresim::testing::TempDir;
using mresim::testing::write_text;

// `program args...` in `dir`, waited for; stdout and stderr through .stdout-sweep/.stderr-sweep.
CommandResult run_sweep_program(const fs::path& program, const fs::path& dir,
                                const std::vector<std::string>& args) {
  return mresim::testing::run_program(program, dir, args, "-sweep");
}

CommandResult run_mresim_sweep(const fs::path& dir, const std::vector<std::string>& args) {
  return run_sweep_program(MRESIM_CLI_PATH, dir, args);
}

// Four points: springs.k x field.angle.
const char* const kSweep =
    "[run]\n"
    "type = \"pair_hysteresis\"\n"
    "[material]\n"
    "radius = 1.5e-6\n"
    "saturation_magnetization = 1.4e6\n"
    "susceptibility = 2.0\n"
    "[springs]\n"
    "model = \"single\"\n"
    "k = 4e-2\n"
    "rest_separation = 9e-6\n"
    "[field]\n"
    "max = 0.5\n"
    "step = 0.1\n"
    "angle = 0.0\n"
    "[sweep]\n"
    "product = { \"springs.k\" = [2e-2, 4e-2], \"field.angle\" = [0.0, 60.0] }\n";

const std::vector<std::string> kPoints = {"point-0000", "point-0001", "point-0002", "point-0003"};

bool present(const fs::path& p) {
  std::error_code ec;
  return fs::exists(p, ec);
}

TEST(CliSweep, RunsEveryPointRecordsItsParametersAndCollects) {
  const TempDir dir;
  write_text(dir / "s.toml", kSweep);
  const CommandResult r =
      run_mresim_sweep(dir.path(), {"sweep", "s.toml", "--out", "out", "--jobs", "2"});
  ASSERT_EQ(r.status, 0) << r.err << r.out;
  EXPECT_NE(r.out.find("4 point(s): 4 ran, 0 failed"), std::string::npos) << r.out;
  for (const auto& p : kPoints) EXPECT_TRUE(present(dir / "out" / p / "results.h5")) << p;

  const auto record = nlohmann::json::parse(read_text(dir / "out/sweep.json"));
  EXPECT_EQ(record["keys"], (nlohmann::json{"springs.k", "field.angle"}));
  EXPECT_EQ(record["points"][2]["parameters"]["springs.k"], 0.04);
  EXPECT_EQ(record["points"][2]["parameters"]["field.angle"], 0.0);
  EXPECT_EQ(record["points"][2]["directory"], "point-0002");
  const Hdf5Reader results(dir / "out/point-0002/results.h5");
  EXPECT_EQ(results.string_attribute("/", "input_overrides"), "springs.k=0.04\nfield.angle=0.0\n");

  const std::string points = read_text(dir / "out/collected_points.csv");
  EXPECT_EQ(points.substr(0, points.find('\n')),
            "point,directory,status,exit_status,message,springs.k,field.angle");
  EXPECT_NE(points.find("\n3,point-0003,finished,0,,0.04,60\n"), std::string::npos) << points;
  EXPECT_TRUE(present(dir / "out/collected.h5"));
}

TEST(CliSweep, SkipsFinishedPointsWhenRunAgain) {
  const TempDir dir;
  write_text(dir / "s.toml", kSweep);
  ASSERT_EQ(
      run_mresim_sweep(dir.path(), {"sweep", "s.toml", "--out", "out", "--index", "1"}).status, 0);
  const auto first = fs::last_write_time(dir / "out/point-0001/results.h5");
  const CommandResult r = run_mresim_sweep(dir.path(), {"sweep", "s.toml", "--out", "out"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("4 point(s): 3 ran, 0 failed, 1 already finished (skipped)"),
            std::string::npos)
      << r.out;
  EXPECT_EQ(fs::last_write_time(dir / "out/point-0001/results.h5"), first);

  // Another sweep into the same directory is refused: its points would not match.
  std::string other = kSweep;
  other.replace(other.find("60.0"), 4, "30.0");
  write_text(dir / "other.toml", other);
  const CommandResult refused =
      run_mresim_sweep(dir.path(), {"sweep", "other.toml", "--out", "out"});
  EXPECT_EQ(refused.status, 2);
  EXPECT_NE(refused.err.find("'out' holds another sweep"), std::string::npos) << refused.err;
}

TEST(CliSweep, AFailedPointIsReportedAndTheOthersStillRun) {
  const TempDir dir;
  write_text(dir / "s.toml", kSweep);
  ASSERT_EQ(
      run_mresim_sweep(dir.path(), {"sweep", "s.toml", "--out", "out", "--index", "0"}).status, 0);
  // Point 2's directory holds a file of the user's: its `mresim run` refuses it (status 2).
  fs::create_directories(dir / "out/point-0002");
  write_text(dir / "out/point-0002/notes.txt", "mine");
  const CommandResult r = run_mresim_sweep(dir.path(), {"sweep", "s.toml", "--out", "out"});
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_NE(r.err.find("sweep point 2 (springs.k=0.04, field.angle=0.0) failed with exit status 2"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.out.find("4 point(s): 3 ran, 1 failed, 1 already finished"), std::string::npos)
      << r.out;
  EXPECT_TRUE(present(dir / "out/point-0003/results.h5"));
  EXPECT_EQ(read_text(dir / "out/point-0002/notes.txt"), "mine");
  const std::string points = read_text(dir / "out/collected_points.csv");
  EXPECT_NE(points.find("\n2,point-0002,failed,2,"), std::string::npos) << points;
  EXPECT_NE(points.find("was not written by mresim"), std::string::npos) << points;

  // `mresim collect` lists it too, and a table of the points' results has its row, empty.
  const CommandResult c = run_mresim_sweep(dir.path(), {"collect", "out"});
  EXPECT_EQ(c.status, 0) << c.err;
  EXPECT_NE(c.out.find("3 point(s) finished (0 with invalid results), 1 failed, 0 not run yet"),
            std::string::npos)
      << c.out;
}

TEST(CliSweep, IndexRunsExactlyOnePointAndNoCollect) {
  const TempDir dir;
  write_text(dir / "s.toml", kSweep);
  const CommandResult r =
      run_mresim_sweep(dir.path(), {"sweep", "s.toml", "--out", "out", "--index", "3"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(present(dir / "out/point-0003/results.h5"));
  for (const char* p : {"point-0000", "point-0001", "point-0002"})
    EXPECT_FALSE(present(dir / "out" / p));
  EXPECT_FALSE(present(dir / "out/collected_points.csv"));
  EXPECT_EQ(read_text(dir / "out/logs/point-0003.status"), "0\n");

  // collect afterwards lists the three others as pending, with empty cells.
  ASSERT_EQ(run_mresim_sweep(dir.path(), {"collect", "out"}).status, 0);
  const std::string points = read_text(dir / "out/collected_points.csv");
  EXPECT_NE(points.find("\n0,point-0000,pending,,,0.02,0\n"), std::string::npos) << points;
}

TEST(CliSweep, AnIndexPastTheLastPointIsRefusedAndNothingIsWritten) {
  const TempDir dir;
  write_text(dir / "s.toml", kSweep);
  const CommandResult r =
      run_mresim_sweep(dir.path(), {"sweep", "s.toml", "--out", "out", "--index", "4"});
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.err, "mresim: error: --index 4: the sweep has 4 point(s), numbered 0 to 3\n");
  EXPECT_FALSE(present(dir / "out"));
}

// mpirun -np 2: each rank runs every second point, rank 0 collects; the tables equal those of
// a sweep in one process.
TEST(CliSweep, TwoMpiRanksCollectTheSameTablesAsOneProcess) {
  const fs::path mpirun = MRESIM_MPIEXEC;  // CMake's MPIEXEC_EXECUTABLE
  if (mpirun.empty() || !present(mpirun)) GTEST_SKIP() << "no MPI launcher (mpirun) found";
  const TempDir dir;
  write_text(dir / "s.toml", kSweep);
  const CommandResult serial = run_mresim_sweep(dir.path(), {"sweep", "s.toml", "--out", "serial"});
  ASSERT_EQ(serial.status, 0) << serial.err;
  const CommandResult mpi = run_sweep_program(mpirun, dir.path(),
                                              {"--allow-run-as-root", "--oversubscribe", "-np", "2",
                                               MRESIM_CLI_PATH, "sweep", "s.toml", "--out", "mpi"});
  ASSERT_EQ(mpi.status, 0) << mpi.err << mpi.out;
  // Rank 0's summary counts the points of both ranks.
  EXPECT_NE(mpi.out.find("4 point(s): 4 ran, 0 failed"), std::string::npos) << mpi.out;
  int tables = 0;
  for (const auto& entry : fs::directory_iterator(dir / "serial")) {
    const std::string name = entry.path().filename().string();
    if (!name.starts_with("collected_")) continue;
    ++tables;
    EXPECT_EQ(read_text(dir / "mpi" / name), read_text(entry.path())) << name;
  }
  EXPECT_GE(tables, 2);
}

}  // namespace
