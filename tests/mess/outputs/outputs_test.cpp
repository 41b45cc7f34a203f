// The output directory of a 3D run (docs/outputs-3d.md): results.h5 datasets and their sizes,
// summary.csv, and the XDMF view of the deformed lattice (cells in VTK hexahedron order, one
// positions file per step), read back without the writer's code.

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>

#include "../../support/hdf5_read.hpp"
#include "../../support/temp_dir.hpp"
#include "../support/small_runs.hpp"

namespace {

namespace fs = std::filesystem;
using mresim::testing::Hdf5Reader;
using mresim::testing::read_text;
using mresim::testing::TempDir;

TEST(MessOutputs, ResultsSummaryAndXdmfAreConsistent) {
  const TempDir dir;
  std::string toml = mresim::mess_protocol::testing::small_hysteresis(0.1, 1);
  toml += "node_positions = true\n";  // appended to [output]
  std::ofstream(dir / "run.toml") << toml;
  const std::string command = "cd '" + dir.path().string() + "' && '" + MRESIM_CLI_PATH +
                              "' run run.toml --out out --no-plot -j 2 >/dev/null 2>&1";
  const int raw = std::system(command.c_str());
  ASSERT_TRUE(WIFEXITED(raw) && WEXITSTATUS(raw) == 0);

  const fs::path out = dir / "out";
  const std::size_t steps = 6;  // loop over 0, 0.1 T: 5 x 1 + 1
  const Hdf5Reader h5(out / "results.h5");
  EXPECT_EQ(h5.doubles("/steps/energies/total").size(), steps);
  EXPECT_EQ(h5.shape("/steps/centres"), (std::vector<hsize_t>{steps, 2, 3}));
  EXPECT_EQ(h5.shape("/steps/cluster_id"), (std::vector<hsize_t>{steps, 2}));
  EXPECT_EQ(h5.strings("/steps/solver/status").size(), steps);
  // Physical profile, L-BFGS without a fallback: L-BFGS finished every step, no seed passes.
  EXPECT_EQ(h5.strings("/steps/solver/finished_by"), std::vector<std::string>(steps, "lbfgs"));
  EXPECT_EQ(h5.ints("/steps/solver/correction_passes"), std::vector<std::int64_t>(steps, 0));
  // A field loop: the first step from the lattice, the second from the step before, the later
  // ones from the field secant through the two steps before (solver.field_step_start). It is
  // kept where the loop turns (0.1 -> 0 T: back to the 0 T state) and rejected where the field
  // passes zero (0 -> -0.1 T, 0 -> 0.1 T: the pair's response is even in B, so the secant points
  // the wrong way).
  const std::vector<std::string> start = {"initial_lattice", "previous",
                                          "field_secant",    "previous_prediction_rejected",
                                          "field_secant",    "previous_prediction_rejected"};
  EXPECT_EQ(h5.strings("/steps/solver/start"), start);
  // The measured peak memory of the run, absolute and per node: the
  // process held at least its lattice (positions alone are 24 bytes per node).
  const auto peak = static_cast<double>(
      h5.scalar_attribute<long long>("/", "peak_resident_memory_bytes", H5T_NATIVE_LLONG));
  const auto per_node =
      h5.scalar_attribute<double>("/", "peak_resident_memory_bytes_per_node", H5T_NATIVE_DOUBLE);
  EXPECT_GT(per_node, 24.0);
  EXPECT_NEAR(per_node * static_cast<double>(h5.shape("/lattice/initial_positions")[0]), peak,
              1e-6 * peak);
  // Per step, the peak so far: positive, never falling, and the last one at most the run's
  // (the run's is measured later, after the outputs were written).
  const auto step_peaks = h5.ints("/steps/solver/peak_resident_memory");
  ASSERT_EQ(step_peaks.size(), steps);
  EXPECT_GT(step_peaks.front(), 0);
  for (std::size_t s = 1; s < steps; ++s) EXPECT_GE(step_peaks[s], step_peaks[s - 1]) << s;
  EXPECT_LE(static_cast<double>(step_peaks.back()), peak);
  // The energy terms add up to the total (self_linearized is reported only).
  const auto total = h5.doubles("/steps/energies/total");
  for (std::size_t s = 0; s < steps; ++s) {
    double sum = 0.0;
    for (const char* t : {"springs", "volume", "zeeman", "dipole", "self", "wca", "load"}) {
      sum += h5.doubles(std::string("/steps/energies/") + t)[s];
    }
    EXPECT_NEAR(sum, total[s], 1e-12 * std::abs(total[s]) + 1e-30);
  }

  // summary.csv: header plus one row per step.
  const std::string csv = read_text(out / "summary.csv");
  EXPECT_EQ(static_cast<std::size_t>(std::count(csv.begin(), csv.end(), '\n')), steps + 1);

  // XDMF: one grid per step, each geometry file present with N x 3 positions.
  const std::string xdmf = read_text(out / "mess.xdmf");
  std::size_t grids = 0;
  for (std::size_t pos = 0; (pos = xdmf.find("GridType=\"Uniform\"", pos)) != std::string::npos;
       ++pos) {
    ++grids;
  }
  EXPECT_EQ(grids, steps);
  const auto nodes = static_cast<hsize_t>(h5.ints("/lattice/particle_id").size());
  const auto cells = h5.shape("/lattice/cells");
  ASSERT_EQ(cells.size(), 2U);
  EXPECT_EQ(cells[1], 8U);
  EXPECT_NE(xdmf.find("NumberOfElements=\"" + std::to_string(cells[0]) + "\""), std::string::npos);
  for (std::size_t s = 0; s < steps; ++s) {
    char name[32];
    std::snprintf(name, sizeof name, "step_%06zu.h5", s);
    EXPECT_NE(xdmf.find(std::string("positions/") + name), std::string::npos) << name;
    const Hdf5Reader p(out / "positions" / name);
    EXPECT_EQ(p.shape("/positions"), (std::vector<hsize_t>{nodes, 3}));
  }
  // H5MD: the particle trajectory in nm, step and time the step index, the field an observable.
  const auto centres = h5.doubles("/steps/centres");
  const auto position = h5.doubles("/particles/magnetic_particles/position/value");
  ASSERT_EQ(position.size(), centres.size());
  for (std::size_t i = 0; i < centres.size(); ++i) {
    EXPECT_NEAR(position[i], centres[i] * 1e9, 1e-9 * std::abs(position[i]));
  }
  EXPECT_EQ(h5.ints("/particles/magnetic_particles/position/step"), h5.ints("/steps/index"));
  EXPECT_EQ(h5.doubles("/observables/field/value"), h5.doubles("/steps/field"));
  EXPECT_EQ(h5.shape("/particles/nodes/position/value"), (std::vector<hsize_t>{steps, nodes, 3}));
  // The particle glyphs: one polyvertex grid per step, and three legs timed by the field
  // (0 -> 0.1, 0.1 -> -0.1 turning at 0.1, -0.1 -> 0.1).
  const std::string particles = read_text(out / "particles.xdmf");
  EXPECT_NE(particles.find("TopologyType=\"Polyvertex\" NumberOfElements=\"2\""),
            std::string::npos);
  EXPECT_NE(particles.find("results.h5:/steps/magnetization"), std::string::npos);
  EXPECT_TRUE(fs::exists(out / "xdmf" / "lattice_leg_02.xdmf"));
  EXPECT_FALSE(fs::exists(out / "xdmf" / "lattice_leg_03.xdmf"));
  EXPECT_NE(read_text(out / "xdmf" / "particles_leg_01.xdmf").find("<Time Value=\"-0.1\"/>"),
            std::string::npos);

  // VTK hexahedron order: from vertex 0, vertex 1 is +x, vertex 3 is +y, vertex 4 is +z.
  const auto c = h5.ints("/lattice/cells");
  const auto x0 = h5.doubles("/lattice/initial_positions");
  const auto at = [&](std::int64_t node, int axis) {
    return x0[static_cast<std::size_t>(3 * node + axis)];
  };
  const double le = 1e-6;
  EXPECT_NEAR(at(c[1], 0) - at(c[0], 0), le, 1e-15);
  EXPECT_NEAR(at(c[3], 1) - at(c[0], 1), le, 1e-15);
  EXPECT_NEAR(at(c[4], 2) - at(c[0], 2), le, 1e-15);
  EXPECT_NEAR(at(c[6], 0) - at(c[0], 0), le, 1e-15);
  EXPECT_NEAR(at(c[6], 1) - at(c[0], 1), le, 1e-15);
  EXPECT_NEAR(at(c[6], 2) - at(c[0], 2), le, 1e-15);
}

// Without node positions per step the initial lattice is still written (the initial-
// configuration figures need it), but no cells, positions files or XDMF.
TEST(MessOutputs, InitialLatticeIsWrittenWithoutNodePositions) {
  const TempDir dir;
  std::ofstream(dir / "run.toml") << mresim::mess_protocol::testing::small_hysteresis(0.1, 1);
  const std::string command = "cd '" + dir.path().string() + "' && '" + MRESIM_CLI_PATH +
                              "' run run.toml --out out --no-plot -j 2 >/dev/null 2>&1";
  const int raw = std::system(command.c_str());
  ASSERT_TRUE(WIFEXITED(raw) && WEXITSTATUS(raw) == 0);

  const fs::path out = dir / "out";
  const Hdf5Reader h5(out / "results.h5");
  const auto particle_id = h5.ints("/lattice/particle_id");
  const auto nodes = static_cast<hsize_t>(particle_id.size());
  EXPECT_GT(nodes, 0U);
  EXPECT_EQ(h5.shape("/lattice/initial_positions"), (std::vector<hsize_t>{nodes, 3}));
  // Both particles have nodes, and most nodes are polymer (-1).
  EXPECT_EQ(*std::max_element(particle_id.begin(), particle_id.end()), 1);
  EXPECT_GT(std::count(particle_id.begin(), particle_id.end(), -1),
            static_cast<std::ptrdiff_t>(nodes / 2));
  EXPECT_FALSE(fs::exists(out / "mess.xdmf"));
  EXPECT_FALSE(fs::exists(out / "positions"));
}

}  // namespace
