// Invalid results of the 3D runs (docs/outputs-3d.md, "Invalid results"): parameters whose
// energy scales overflow are refused by the run-file reader (exit status 2, naming the key);
// non-finite and unconverged steps are written marked (/steps/valid, summary.csv `valid`) and
// end `mresim run` with status 4; modulus fits carry points, residual and a valid flag.

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "../../support/hdf5_read.hpp"
#include "../../support/temp_dir.hpp"
#include "../support/cli_run.hpp"
#include "../support/small_runs.hpp"
#include "mresim/config/config_error.hpp"
#include "mresim/mess/outputs/mess_outputs.hpp"

namespace mresim::mess_protocol {
namespace {

namespace fs = std::filesystem;
using mresim::mess_protocol::testing::CliRun;
using mresim::mess_protocol::testing::column_of;
using mresim::mess_protocol::testing::csv_rows;
using mresim::mess_protocol::testing::run_in;
using mresim::testing::Hdf5Reader;
using mresim::testing::read_text;
using mresim::testing::TempDir;

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  if (at == std::string::npos) throw std::logic_error("replaced: '" + from + "' not found");
  return text.replace(at, from.size(), to);
}

// ------------------------------------------------------------------ validation (exit 2)

TEST(MessValidation, SaturationMagnetizationThatOverflowsIsRefused) {
  const std::string toml = replaced(testing::small_hysteresis(0.01, 1), "placement = \"chain\"",
                                    "saturation_magnetization = 1e308\nplacement = \"chain\"");
  try {
    (void)testing::spec_of(toml);
    FAIL() << "Ms = 1e308 accepted";
  } catch (const config::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("particles.saturation_magnetization = 1e+308"),
              std::string::npos)
        << e.what();
  }
  const TempDir dir;
  const CliRun r = run_in(dir, toml);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("particles.saturation_magnetization = 1e+308"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "out" / "results.h5"));
  // 1e150 A/m still overflows the squared force scale; iron's value does not.
  EXPECT_THROW((void)testing::spec_of(replaced(toml, "1e308", "1e150")), config::ConfigError);
  EXPECT_NO_THROW((void)testing::spec_of(replaced(toml, "1e308", "1.6e6")));
}

TEST(MessValidation, YoungsModulusThatOverflowsIsRefused) {
  const std::string toml = replaced(testing::small_hysteresis(0.01, 1), "discretization_order = 1",
                                    "discretization_order = 1\nyoungs_modulus = 1e308");
  const TempDir dir;
  const CliRun r = run_in(dir, toml);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("model.youngs_modulus = 1e+308"), std::string::npos) << r.err;
  EXPECT_NO_THROW((void)testing::spec_of(replaced(toml, "1e308", "1e6")));
}

TEST(MessValidation, LeapfrogStepAboveTheSeedStabilityLimitIsRefused) {
  // Seed profile, n_d = 2: dt < 4.8e-3 t_c (the default 5e-3 too is refused there).
  std::string toml =
      replaced(testing::small_hysteresis(0.01, 1), "profile = \"physical\"", "profile = \"seed\"");
  toml = replaced(toml, "discretization_order = 1", "discretization_order = 2");
  toml += "\n[solver]\nmethod = \"leapfrog\"\n[solver.leapfrog]\ndt = 0.1\n";
  try {
    (void)testing::spec_of(toml);
    FAIL() << "dt = 0.1 accepted";
  } catch (const config::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("solver.leapfrog.dt = 0.1: must be < 0.0048"),
              std::string::npos)
        << e.what();
  }
  EXPECT_NO_THROW((void)testing::spec_of(replaced(toml, "dt = 0.1", "dt = 4e-3")));
}

// ------------------------------------------------------------ step checks (unit level)

TEST(MessInvalidResults, CheckStepsNamesNonFiniteAndUnconvergedSteps) {
  const mess_config::MessSpec spec = testing::spec_of(testing::small_hysteresis(0.02, 1));
  std::vector<StepRecord> records(4);
  for (std::size_t i = 0; i < records.size(); ++i) {
    records[i].step.index = i;
    records[i].step.field = Eigen::Vector3d(0.0, 0.0, 0.01 * static_cast<double>(i));
    records[i].converged = true;
    records[i].status = "converged";
    records[i].system_volume = 1e-15;
    records[i].centres = Eigen::Matrix3Xd::Zero(3, 2);
    records[i].magnetization = Eigen::Matrix3Xd::Zero(3, 2);
    records[i].energies = mess::MessEnergies::of({{"springs", "eq. 4.62", "springs", true}});
  }
  records[1].energies["springs"] = std::numeric_limits<double>::infinity();
  records[1].centres(2, 1) = std::numeric_limits<double>::quiet_NaN();
  records[2].converged = false;
  records[2].status = "max_iterations";

  MessResultCheck check;
  const std::vector<std::int64_t> valid = check_steps(spec, records, check);
  EXPECT_EQ(valid, (std::vector<std::int64_t>{1, 0, 0, 1}));
  EXPECT_EQ(check.non_finite.count(), 1U);
  EXPECT_EQ(check.unconverged.count(), 1U);
  const std::string message = check.message();
  EXPECT_NE(message.find("non-finite results: energy, particle centres at step 1 (B = 0.01 T)"),
            std::string::npos)
      << message;
  EXPECT_NE(message.find("unconverged steps: relaxation (max_iterations) at step 2 (B = 0.02 T)"),
            std::string::npos)
      << message;

  // Written as NaN, not inf.
  const std::vector<StepRecord> written = with_nan_for_non_finite(records);
  EXPECT_TRUE(std::isnan(written[1].energies["springs"]));
  EXPECT_TRUE(std::isnan(written[1].centres(2, 1)));
  EXPECT_EQ(written[0].energies["springs"], 0.0);

  // Relaxation converged, the final magnetization solve did not: named as such.
  records[3].converged = false;
  records[3].magnetization_method = "newton";
  records[3].magnetization_residual = 0.5;
  MessResultCheck solve;
  (void)check_steps(spec, {records[3]}, solve);
  EXPECT_NE(solve.message().find("final magnetization solve (newton, residual 0.5 Ms) at step 3"),
            std::string::npos)
      << solve.message();
  records[3].converged = true;

  MessResultCheck clean;
  (void)check_steps(spec, {records[0], records[3]}, clean);
  EXPECT_EQ(clean.message(), "");
}

// ------------------------------------------------------------ whole runs (exit 4)

// The physical profile at n_d = 1 has no known leapfrog limit, so dt = 0.1 t_c passes the
// reader; the integration blows up and every step is non-finite.
TEST(MessInvalidResults, LeapfrogBlowUpIsPublishedMarkedAndExitsFour) {
  const std::string toml = testing::small_hysteresis(0.01, 1, 0) +
                           "\n[solver]\nmethod = \"leapfrog\"\n[solver.leapfrog]\ndt = 0.1\n"
                           "steps_per_round = 200\nmax_rounds = 4\n";
  const TempDir dir;
  const CliRun r = run_in(dir, toml);
  ASSERT_EQ(r.status, 4) << r.err;
  EXPECT_NE(r.err.find("non-finite results: "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("at step 0 (B = 0 T)"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("see /steps/valid"), std::string::npos) << r.err;

  const fs::path out = dir / "out";
  const Hdf5Reader h5(out / "results.h5");
  const auto valid = h5.ints("/steps/valid");
  ASSERT_EQ(valid.size(), 6U);  // 0 -> 0.01 -> -0.01 -> 0.01 T
  for (const auto v : valid) EXPECT_EQ(v, 0);
  for (const double e : h5.doubles("/steps/energies/total")) {
    EXPECT_FALSE(std::isinf(e));  // non-finite is written as NaN
  }
  const auto rows = csv_rows(out / "summary.csv");
  ASSERT_EQ(rows.size(), 7U);
  const std::size_t v = column_of(rows[0], "valid");
  for (std::size_t i = 1; i < rows.size(); ++i) EXPECT_EQ(rows[i][v], "0");
}

// A strain run whose minimiser stops after one iteration: every loaded step is unconverged
// (the unloaded one at zero field is at rest already), the run exits 4, and modulus.csv marks the
// fits (points, residual, valid).
TEST(MessInvalidResults, UnconvergedStrainRunExitsFourWithInvalidModuli) {
  const std::string strain = std::string("[run]\ntype = \"mess_strain\"\n") + testing::kSmallModel +
                             "\n[field]\nmagnitudes = [0.0]\n"
                             "\n[strain]\nkind = \"shear\"\nmax = 0.02\nsteps = 3\n"
                             "\n[output]\ncheckpoint_every = 0\n";
  const TempDir dir;
  const CliRun r = run_in(dir, strain + "\n[solver]\n[solver.minimiser]\nmax_iterations = 1\n");
  ASSERT_EQ(r.status, 4) << r.err;
  EXPECT_NE(
      r.err.find(
          "unconverged steps: relaxation (max_iterations) at step 1 (B = 0 T, load 0.006667 rad)"),
      std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("invalid modulus fit, not a result: G_eff at |B| = 0 T (field 0)"),
            std::string::npos)
      << r.err;
  const auto rows = csv_rows(dir / "out" / "modulus.csv");
  ASSERT_EQ(rows.size(), 2U);
  EXPECT_EQ(rows[1][column_of(rows[0], "valid")], "0");
  EXPECT_GE(std::stoi(rows[1][column_of(rows[0], "points")]), 3);
  const Hdf5Reader h5(dir / "out" / "results.h5");
  EXPECT_EQ(h5.ints("/analysis/valid"), (std::vector<std::int64_t>{0}));
  EXPECT_NE(h5.strings("/analysis/problem")[0].find("did not converge"), std::string::npos);
}

// The same run converged: exit 0, every step and the fit valid, and modulus.csv has the
// columns points, residual and valid.
TEST(MessOutputs, ModulusCsvHasPointsResidualAndValid) {
  const std::string strain = std::string("[run]\ntype = \"mess_strain\"\n") + testing::kSmallModel +
                             "\n[field]\nmagnitudes = [0.0]\n"
                             "\n[strain]\nkind = \"shear\"\nmax = 0.02\nsteps = 3\n"
                             "\n[output]\ncheckpoint_every = 0\n";
  const TempDir dir;
  const CliRun r = run_in(dir, strain);
  ASSERT_EQ(r.status, 0) << r.err;
  const auto rows = csv_rows(dir / "out" / "modulus.csv");
  ASSERT_EQ(rows.size(), 2U);
  const auto& header = rows[0];
  EXPECT_EQ(rows[1][column_of(header, "valid")], "1");
  EXPECT_EQ(rows[1][column_of(header, "points")], "4");
  EXPECT_GT(std::stod(rows[1][column_of(header, "G_eff_Pa")]), 0.0);
  EXPECT_GE(std::stod(rows[1][column_of(header, "residual")]), 0.0);
  const Hdf5Reader h5(dir / "out" / "results.h5");
  EXPECT_EQ(h5.ints("/steps/valid"), (std::vector<std::int64_t>{1, 1, 1, 1}));
  EXPECT_EQ(h5.ints("/analysis/valid"), (std::vector<std::int64_t>{1}));
  EXPECT_EQ(h5.strings("/analysis/problem")[0], "");
  // No kink on a polymer-dominated parabola: no second fit, NaN numbers, valid 0.
  EXPECT_EQ(rows[1][column_of(header, "second_valid")], "0");
  EXPECT_EQ(rows[1][column_of(header, "second_points")], "0");
  EXPECT_TRUE(std::isnan(std::stod(rows[1][column_of(header, "second_modulus")])));
  EXPECT_EQ(h5.ints("/analysis/second_valid"), (std::vector<std::int64_t>{0}));
  EXPECT_TRUE(std::isnan(h5.doubles("/analysis/second_modulus")[0]));
  EXPECT_EQ(h5.strings("/analysis/second_problem")[0], "no kink");
}

}  // namespace
}  // namespace mresim::mess_protocol
