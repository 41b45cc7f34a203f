// 3D run files that used to change the input silently, blame the wrong key, fail with exit 1
// naming no key, or die of std::bad_alloc: the actual volume fraction of an anisotropic box is
// warned about (stderr and results.h5 /@warnings), a subnormal radius and overflowing fields and
// stresses are refused on their own keys, a misspelt required key is named, and a lattice that
// does not fit in memory is refused before anything is written.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <optional>
#include <string>

#include "../../support/hdf5_read.hpp"
#include "../../support/run_file_edits.hpp"
#include "../../support/temp_dir.hpp"
#include "../support/mess_run_file.hpp"
#include "../support/small_runs.hpp"
#include "mresim/mess/run_file/mess_spec.hpp"
#include "mresim/mess/solvers/minimiser.hpp"

namespace {

namespace mc = mresim::mess_config;
using mresim::config::ConfigError;
using mresim::testing::edit;
using mresim::testing::read_spec;
using mresim::testing::read_text;
using mresim::testing::spec_error_of;
using mresim::testing::TempDir;
using mresim::testing::write_text;

// Two particles of order 1 in a box sized for Phi = 0.02 with factors [1, 1, 2]: the box is twice
// as long along z, so Phi is halved (10 x 10 x 37 nodes, actual Phi 0.00969627).
const std::string kAnisotropic = R"([run]
type = "mess_hysteresis"
[model]
discretization_order = 1
[particles]
placement = "regular_anisotropic"
volume_fraction = 0.02
count_per_axis = [1, 1, 2]
anisotropy_factor = [1, 1, 2]
[field]
max = 0.05
steps = 1
[output]
checkpoint_every = 0
)";

const std::string kAnisotropyWarning =
    "particles.volume_fraction = 0.02 with particles.anisotropy_factor = [1, 1, 2]: the "
    "lattice's actual volume fraction is 0.00969627, not 0.02 (-51.5 %): the box side along "
    "each axis is n_a s f_a, so the factors' product fx fy fz = 2 divides the volume fraction (a "
    "single number f, sides 1/sqrt(f), 1/sqrt(f), f, keeps it); rounding the box to whole "
    "lattice spacings (l_e = 1e-06 m, 10 x 10 x 37 nodes) changes the box volume by a factor "
    "1.03132";

struct Cli {
  int status = -1;
  std::string err;
};

// `env mresim ARGS` in `dir`, stdout discarded, stderr captured.
Cli run_cli(const TempDir& dir, const std::string& args, const std::string& env = "") {
  const std::string command = "cd '" + dir.path().string() + "' && " + env + " '" +
                              MRESIM_CLI_PATH + "' " + args + " >/dev/null 2>err.txt";
  const int raw = std::system(command.c_str());
  Cli out;
  if (WIFEXITED(raw)) out.status = WEXITSTATUS(raw);
  out.err = read_text(dir / "err.txt");
  return out;
}

// ------------------------------------------------------------------- A. actual volume fraction

TEST(MessInputWarnings, AnisotropyFactorsWhoseProductIsNotOneAreReported) {
  const mc::MessSpec spec = read_spec(kAnisotropic);
  EXPECT_NEAR(spec.geometry.volume_fraction, 0.00969627, 1e-8);
  ASSERT_EQ(spec.warnings.size(), 1U);
  EXPECT_EQ(spec.warnings[0], kAnisotropyWarning);
}

TEST(MessInputWarnings, NoWarningWithinOnePercentOrWithoutAVolumeFraction) {
  // A single factor keeps the volume: Phi = 0.05 at n_d = 5 is 0.050413 (+0.8 %).
  const std::string single =
      edit(edit(kAnisotropic, "anisotropy_factor = [1, 1, 2]", "anisotropy_factor = 2.0"),
           "volume_fraction = 0.02", "volume_fraction = 0.05");
  const mc::MessSpec five = read_spec(edit(single, "discretization_order = 1", ""));
  EXPECT_LT(std::abs(five.geometry.volume_fraction / 0.05 - 1.0), mc::kVolumeFractionTolerance);
  EXPECT_TRUE(five.warnings.empty()) << five.warnings.front();
  // Rounding alone beyond 1 % (Phi = 0.05 at n_d = 1 is 0.0443867) is reported as rounding.
  const mc::MessSpec one = read_spec(edit(
      edit(edit(kAnisotropic, "placement = \"regular_anisotropic\"", "placement = \"regular\""),
           "anisotropy_factor = [1, 1, 2]\n", ""),
      "volume_fraction = 0.02", "volume_fraction = 0.05"));
  ASSERT_EQ(one.warnings.size(), 1U);
  EXPECT_EQ(one.warnings[0].rfind("particles.volume_fraction = 0.05: the lattice's actual volume "
                                  "fraction is 0.0443867, not 0.05 (-11.2 %): rounding the box",
                                  0),
            0U)
      << one.warnings[0];
  // A placement in a given box has no requested volume fraction.
  EXPECT_TRUE(mresim::mess_protocol::testing::spec_of(
                  mresim::mess_protocol::testing::small_hysteresis(0.05, 1))
                  .warnings.empty());
}

TEST(MessInputWarnings, RunPrintsTheWarningAndRecordsItInResults) {
  const TempDir dir;
  write_text(dir / "aniso.toml", kAnisotropic);
  const Cli r = run_cli(dir, "run aniso.toml --out out --no-plot");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("mresim: warning: " + kAnisotropyWarning + "\n"), std::string::npos)
      << r.err;
  const mresim::testing::Hdf5Reader h5(dir / "out" / "results.h5");
  EXPECT_EQ(h5.string_attribute("/", "warnings"), kAnisotropyWarning);

  // `info` lists it too.
  const std::string command =
      "cd '" + dir.path().string() + "' && '" + MRESIM_CLI_PATH + "' info aniso.toml > info.txt";
  ASSERT_EQ(std::system(command.c_str()), 0);
  EXPECT_NE(read_text(dir / "info.txt").find("warning_0"), std::string::npos);
}

TEST(MessInputWarnings, RunWithoutWarningsRecordsAnEmptyAttribute) {
  const TempDir dir;
  write_text(dir / "small.toml", mresim::mess_protocol::testing::small_hysteresis(0.05, 1, 0));
  const Cli r = run_cli(dir, "run small.toml --out out --no-plot");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err.find("warning"), std::string::npos) << r.err;
  const mresim::testing::Hdf5Reader h5(dir / "out" / "results.h5");
  EXPECT_EQ(h5.string_attribute("/", "warnings"), "");
}

// -------------------------------------------------------------------------- B. messages

const std::string kRadiusRule =
    ": must be in [1e-30, 1e+30] m: the lattice spacing l_e = 2R/(2 n_d + 1), the particle "
    "volume 4/3 pi R^3 and the products of two dipole moments (~ Ms^2 R^6) must stay normal "
    "doubles (the particles of an MRE are of order 1e-6 m)";

TEST(MessInputMessages, RadiusOutOfRangeNamesTheRadius) {
  const std::string regular = edit(kAnisotropic, "placement", "radius = 5e-324\nplacement");
  EXPECT_EQ(spec_error_of(regular), "particles.radius = 5e-324" + kRadiusRule);
  EXPECT_EQ(spec_error_of(edit(regular, "5e-324", "1e-300")),
            "particles.radius = 1e-300" + kRadiusRule);
  EXPECT_EQ(spec_error_of(edit(regular, "5e-324", "1e31")),
            "particles.radius = 1e+31" + kRadiusRule);
  // A box placement used to blame box.size.
  const std::string chain = edit(mresim::mess_protocol::testing::small_hysteresis(0.05, 1),
                                 "placement", "radius = 5e-324\nplacement");
  EXPECT_EQ(spec_error_of(chain), "particles.radius = 5e-324" + kRadiusRule);
}

TEST(MessInputMessages, FieldsThatWouldOverflowAreRefusedOnTheirKey) {
  const std::string why =
      "the largest field must be <= 2.87e+10 T (mu0 H): beyond it chi0 H/Ms exceeds 1e+12, "
      "where 1 - |M|/Ms in the self energy's log(1 - |M|/Ms) (eq. 4.76) is below what doubles "
      "resolve (lab fields are below 100 T)";
  EXPECT_EQ(spec_error_of(edit(kAnisotropic, "max = 0.05", "max = 1e308")),
            "field.max = 1e+308: " + why);
  EXPECT_EQ(spec_error_of(edit(kAnisotropic, "max = 0.05\nsteps = 1", "magnitudes = [0.0, 1e11]")),
            "field.magnitudes = [0.0, 100000000000.0]: " + why);
  EXPECT_EQ(spec_error_of(edit(kAnisotropic, "max = 0.05\nsteps = 1", "values = [[0, 0, 1e308]]")),
            "field.values = [[0, 0, 1e+308]]: " + why);
  // Just below the limit is accepted (and runs: 2.8e10 T gives finite results).
  EXPECT_EQ(spec_error_of(edit(kAnisotropic, "max = 0.05", "max = 2.8e10")), "(no error)");
  // A lab field with an absurd chi0 blames chi0.
  EXPECT_EQ(spec_error_of(edit(kAnisotropic, "placement", "susceptibility = 1e200\nplacement")),
            "particles.susceptibility = 1e+200: with the largest field 0.05 T, chi0 H/Ms reaches "
            "2.49e+198, above 1e+12, where 1 - |M|/Ms in the self energy's log(1 - |M|/Ms) (eq. "
            "4.76) is below what doubles resolve; chi0 must be <= 4.02e+13 here (iron's is of "
            "order 1e2-1e3)");
}

TEST(MessInputMessages, StressesBeyondTheLatticeAreRefusedOnTheirKey) {
  const std::string stress = edit(edit(kAnisotropic, "mess_hysteresis", "mess_stress"), "[output]",
                                  "[stress]\nkind = \"tension\"\nmax = 1e308\nsteps = 2\n[output]");
  EXPECT_EQ(
      spec_error_of(stress).rfind("stress.max = 1e+308: the largest stress must be <= 9e+04 Pa: "
                                  "beyond it the traction force on a face node",
                                  0),
      0U)
      << spec_error_of(stress);
  EXPECT_EQ(spec_error_of(edit(stress, "1e308", "1e150")),
            "stress.max = 1e+150: the largest stress must be <= 10 x model.youngs_modulus = "
            "90000 Pa: beyond it the engineering strain (~ stress/E) exceeds 10, far outside the "
            "lattice's small-strain springs, and the relaxation does not converge");
  EXPECT_EQ(spec_error_of(edit(stress, "1e308", "100.0")), "(no error)");
}

TEST(MessInputMessages, MisspeltRequiredKeysAreNamed) {
  EXPECT_EQ(spec_error_of(edit(kAnisotropic, "steps = 1", "stpes = 1")),
            "field.steps = (missing): field.max needs field.steps, the number of increments from "
            "0 to max (integer >= 1); the file has 'field.stpes' - a misspelling?");
  EXPECT_EQ(spec_error_of(edit(kAnisotropic, "count_per_axis", "count_per_axes")),
            "missing key 'particles.count_per_axis' ([nx, ny, nz], particles along x, y and z); "
            "the file has 'particles.count_per_axes' - a misspelling?");
  // Without a look-alike key the message is as before.
  EXPECT_EQ(spec_error_of(edit(kAnisotropic, "steps = 1", "")),
            "field.steps = (missing): field.max needs field.steps, the number of increments from "
            "0 to max (integer >= 1)");
}

// ----------------------------------------------------------------------------- B. memory

TEST(MessMemory, EstimateIsFixedPlusPerNodePlusDenseMagnetization) {
  const mc::MessSpec spec = read_spec(kAnisotropic);  // 3,700 nodes, 2 particles
  EXPECT_EQ(spec.geometry.node_count(), 3700);
  EXPECT_EQ(mc::estimated_memory_bytes(spec), mc::kFixedBytes + 3700 * mc::kBytesPerNode + 32 * 36);
  EXPECT_NO_THROW(mc::check_memory(spec, {mc::estimated_memory_bytes(spec), "test"}));
  // The Newton solver's matrix and multigrid need their own, larger figure per node.
  mc::MessSpec newton = spec;
  newton.solver.method = mc::SolverMethod::newton;
  EXPECT_EQ(mc::estimated_memory_bytes(newton),
            mc::kFixedBytes + 3700 * mc::kNewtonBytesPerNode + 32 * 36);
  // From mess::kMultilevelMinimumNodes on, the default minimiser's multilevel preconditioner
  // fits in the same figure per node as "lbfgs" (measured: 987 bytes per node at 284,592).
  mc::MessSpec large = spec;
  large.geometry.shape.nodes = {40, 40, 25};  // 40,000 nodes
  ASSERT_EQ(large.geometry.node_count(), mresim::mess::kMultilevelMinimumNodes);
  EXPECT_EQ(mc::estimated_memory_bytes(large),
            mc::kFixedBytes + 40000 * mc::kBytesPerNode + 32 * 36);
  large.solver.method = mc::SolverMethod::lbfgs;
  EXPECT_EQ(mc::estimated_memory_bytes(large),
            mc::kFixedBytes + 40000 * mc::kBytesPerNode + 32 * 36);
  // A strain run keeps the latest state and the zero-load reference of every field for its
  // whole length, on disk (48 bytes per node per field), not in memory.
  const std::string strain =
      edit(edit(kAnisotropic, "type = \"mess_hysteresis\"", "type = \"mess_strain\""),
           "[field]\nmax = 0.05\nsteps = 1\n",
           "[field]\nmagnitudes = [0.0, 0.01, 0.02]\n[strain]\nkind = \"shear\"\nnormal = "
           "\"z\"\ndirection = \"x\"\nmax = 0.02\nsteps = 2\n");
  const mc::MessSpec sheared = read_spec(strain);
  ASSERT_EQ(sheared.load_step_count(), 3U);
  EXPECT_EQ(mc::estimated_memory_bytes(sheared),
            mc::kFixedBytes + 3700 * mc::kBytesPerNode + 32 * 36);
  // With the default "extrapolated" starts also each field's result at the strain before, the
  // step's secant and two fields' misses of it.
  ASSERT_TRUE(sheared.keeps_earlier_load_results());
  EXPECT_EQ(mc::scratch_bytes_per_node(sheared),
            3 * (mc::kPerFieldScratchBytesPerNode + mc::kEarlierLoadScratchBytesPerNode) +
                mc::kSecantScratchBytesPerNode);
  const mc::MessSpec sheared_from_previous =
      read_spec(strain + "\n[solver]\nload_step_start = \"previous\"\n");
  EXPECT_EQ(mc::scratch_bytes_per_node(sheared_from_previous),
            3 * mc::kPerFieldScratchBytesPerNode);
  EXPECT_EQ(mc::scratch_bytes_per_node(spec), 0);
  EXPECT_NO_THROW(mc::check_memory(spec, {std::nullopt, "unknown"}));
  try {
    mc::check_memory(spec, {1'000'000, "test"});
    ADD_FAILURE() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()),
              "the lattice of 10 x 10 x 37 = 3700 nodes (2 particles) needs an estimated 35.5 "
              "MiB (32.0 MiB + 1000 bytes per node), more than the 1.0 MiB available to this "
              "process (test); make the box smaller (particles.volume_fraction higher or "
              "count_per_axis lower) or lower model.discretization_order = 1; "
              "MRESIM_MEMORY_LIMIT (bytes) overrides the available figure");
  }
}

TEST(MessMemory, RunBeyondTheLimitIsRefusedBeforeAnythingIsWritten) {
  const TempDir dir;
  write_text(dir / "small.toml", mresim::mess_protocol::testing::small_hysteresis(0.05, 1, 0));
  const Cli r = run_cli(dir, "run small.toml --out out --no-plot", "MRESIM_MEMORY_LIMIT=1000000");
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.err.rfind("mresim: error: the lattice of 10 x 10 x 18 = 1800 nodes (2 particles) "
                        "needs an estimated 33.7 MiB",
                        0),
            0U)
      << r.err;
  EXPECT_NE(r.err.find("1.0 MiB available to this process (MRESIM_MEMORY_LIMIT)"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  for (const auto& entry : std::filesystem::directory_iterator(dir.path())) {
    const std::string name = entry.path().filename().string();
    EXPECT_TRUE(name == "small.toml" || name == "err.txt") << "left behind: " << name;
  }
  // `info` refuses it the same way; with enough memory it shows the estimate.
  EXPECT_EQ(run_cli(dir, "info small.toml", "MRESIM_MEMORY_LIMIT=1000000").status, 2);
  const std::string command = "cd '" + dir.path().string() + "' && MRESIM_MEMORY_LIMIT=1e9 '" +
                              MRESIM_CLI_PATH + "' info small.toml 2>err.txt";
  EXPECT_EQ(std::system(command.c_str()) >> 8, 2);
  EXPECT_NE(read_text(dir / "err.txt")
                .find("MRESIM_MEMORY_LIMIT = \"1e9\": must be a positive "
                      "integer (bytes)"),
            std::string::npos);
  const std::string info = "cd '" + dir.path().string() + "' && MRESIM_MEMORY_LIMIT=900000000 '" +
                           MRESIM_CLI_PATH + "' info small.toml > info.txt";
  ASSERT_EQ(std::system(info.c_str()), 0);
  const std::string text = read_text(dir / "info.txt");
  EXPECT_NE(text.find("estimate   33.7177 MiB"), std::string::npos) << text;
  EXPECT_NE(text.find("available  858.307 MiB  MRESIM_MEMORY_LIMIT"), std::string::npos) << text;
}

}  // namespace
