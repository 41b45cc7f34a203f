// Two-dipole run files whose numbers would overflow the solver's units, vanishing ensemble
// weights, silent changes of the input (S0 inside the WCA cut-off) and non-finite results.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cmath>
#include <limits>
#include <string>

#include "../support/hdf5_read.hpp"
#include "../support/run_file_edits.hpp"
#include "../support/run_plan.hpp"
#include "../support/temp_dir.hpp"
#include "mresim/app/run_type.hpp"
#include "mresim/pair/runs/pair_outputs.hpp"

namespace {

using mresim::config::ConfigError;
using mresim::config::TableReader;
using mresim::testing::edit;
using mresim::testing::run_file_error_of;

const std::string kLoop = R"([run]
type = "pair_hysteresis"
[springs]
model = "single"
k = 4e-2
rest_separation = 9e-6
[field]
max = 0.1
step = 0.01
)";

const std::string kMap = R"([run]
type = "pair_map"
[springs]
model = "three"
shear_modulus = 1375
[field]
max = 0.1
step = 0.01
[map]
rows = "angle"
row_values = [0.0]
separation_min = 3.2e-6
separation_max = 12e-6
separation_count = 2
)";

const std::string kEnsemble = R"([run]
type = "pair_ensemble"
[springs]
k = 9e-3
[field]
max = 0.1
step = 0.01
[ensemble]
separation_min = 3.2e-6
separation_max = 13e-6
separation_count = 3
mean = 4.8e-6
standard_deviation = 6.5e-6
)";

bool starts_with(const std::string& s, const std::string& prefix) {
  return s.rfind(prefix, 0) == 0;
}

struct Refused {
  std::string name;
  std::string text;
  std::string prefix;  // the message starts with the key, the value and the reason
};
void PrintTo(const Refused& r, std::ostream* os) { *os << r.name; }

class PairScaleErrors : public ::testing::TestWithParam<Refused> {};

TEST_P(PairScaleErrors, AreRefusedNamingTheKey) {
  const std::string message = run_file_error_of(GetParam().text);
  EXPECT_TRUE(starts_with(message, GetParam().prefix)) << message;
}

INSTANTIATE_TEST_SUITE_P(
    TwoDipole, PairScaleErrors,
    ::testing::Values(
        Refused{"HugeMs", kLoop + "[material]\nsaturation_magnetization = 1e160\n",
                "material.saturation_magnetization = 1e+160: gives the magnetic energy scale "
                "mu0 Ms^2 V = inf J, outside the range of doubles; at R = 1.5e-06 m Ms must lie "
                "in ["},
        Refused{"TinyRadius", kLoop + "[material]\nradius = 1e-300\n",
                "material.radius = 1e-300: gives the sphere volume V = 4/3 pi R^3 = 0 m^3"},
        Refused{"FarRestSeparation",
                edit(kLoop, "rest_separation = 9e-6", "rest_separation = 1e150"),
                "springs.rest_separation = 1e+150: must be <= 1e+100 R = 1.5e+94 m"},
        Refused{"FarMapSeparation", edit(kMap, "separation_max = 12e-6", "separation_max = 1e200"),
                "map.separation_max = 1e+200: every separation must be <= 1e+100 R"},
        Refused{"HugeStiffnessForTinySpheres",
                edit(kLoop, "k = 4e-2", "k = 1e300") +
                    "[material]\nradius = 1e-100\n[penalty]\ntype = \"wca\"\n",
                "springs.k = 1e+300: gives the spring constant 1e+300 N/m and the spring energy "
                "scale k S0^2"},
        Refused{"HugePenalty", kLoop + "[penalty]\ne_max = 1e300\n",
                "penalty.e_max = 1e+300: is inf times the magnetic energy scale"},
        // field.max is bounded in saturation fields before step and tolerance are checked
        // against it (before: exit 1 "coincident sphere centres", or critical_fields.tolerance
        // blamed).
        Refused{"FieldMaxFarBeyondSaturation", edit(kLoop, "max = 0.1", "max = 1e308"),
                "field.max = 1e+308: must be <= 1e+06 mu0 Ms = 1.75929e+06 T at Ms = 1.4e+06 "
                "A/m (the pair is saturated long before; far beyond, the Zeeman energy swamps "
                "every other term of the solver)"},
        Refused{"FieldMaxBeforeTolerance",
                edit(kLoop, "max = 0.1\nstep = 0.01", "max = 1e308\nstep = 1e306") +
                    "[critical_fields]\ntolerance = 1e-4\n",
                "field.max = 1e+308: must be <= 1e+06 mu0 Ms"},
        Refused{"FieldMaxJustAboveTheBound",
                edit(kLoop, "max = 0.1\nstep = 0.01", "max = 1.8e6\nstep = 1e5"),
                "field.max = 1800000: must be <= 1e+06 mu0 Ms = 1.75929e+06 T"},
        Refused{"FieldMaxForSmallerMsInACase",
                edit(kLoop, "max = 0.1\nstep = 0.01", "max = 1e5\nstep = 1e4") +
                    "[[case]]\nlabel = \"soft\"\n[case.material]\nsaturation_magnetization = "
                    "1e4\n",
                "case[0].field.max = 100000: must be <= 1e+06 mu0 Ms = 12566.4 T at Ms = 10000 "
                "A/m"},
        Refused{"MapFieldMax",
                edit(kMap, "max = 0.1\nstep = 0.01", "max = 1e308\nstep = 1e302") +
                    "[critical_fields]\ntolerance = 1e-4\n",
                "field.max = 1e+308: must be <= 1e+06 mu0 Ms"},
        Refused{"EnsembleFieldMax",
                edit(kEnsemble, "max = 0.1\nstep = 0.01", "max = 1e308\nstep = 1e307"),
                "field.max = 1e+308: must be <= 1e+06 mu0 Ms"},
        Refused{"EnsembleMeanInMicrometres", edit(kEnsemble, "mean = 4.8e-6", "mean = 4.8"),
                "ensemble.mean = 4.8: the Gaussian weights exp(-(S0 - mean)^2 / (2 sd^2)) with "
                "mean = 4.8 m, standard_deviation = 6.5e-06 m vanish at every separation from "
                "3.2e-06 to 1.3e-05 m; mean and standard_deviation are in metres"},
        Refused{"EnsembleWidthFarTooNarrow",
                edit(edit(kEnsemble, "standard_deviation = 6.5e-6", "standard_deviation = 1e-9"),
                     "mean = 4.8e-6", "mean = 5.6e-6"),
                "ensemble.standard_deviation = 1e-09: the Gaussian weights"}),
    [](const auto& info) { return info.param.name; });

// Through the command line: exit status 2, one line naming the key, and nothing written (before
// the fix these aborted with status 134 and left out.partial-<pid> behind).
TEST(PairScaleErrors, CommandLineRefusesThemWithStatus2) {
  const std::vector<std::pair<std::string, std::string>> files{
      {edit(kLoop, "rest_separation = 9e-6", "rest_separation = 1e150"),
       "mresim: error: springs.rest_separation = 1e+150: "},
      {kLoop + "[material]\nradius = 1e-300\n", "mresim: error: material.radius = 1e-300: "},
      {edit(kMap, "separation_max = 12e-6", "separation_max = 1e200"),
       "mresim: error: map.separation_max = 1e+200: "},
      {edit(kLoop, "max = 0.1\nstep = 0.01", "max = 1e308\nstep = 1e307"),
       "mresim: error: field.max = 1e+308: must be <= 1e+06 mu0 Ms"}};
  for (const auto& [text, prefix] : files) {
    const mresim::testing::TempDir dir;
    mresim::testing::write_text(dir / "bad.toml", text);
    const std::string command = "cd '" + dir.path().string() + "' && '" + MRESIM_CLI_PATH +
                                "' run bad.toml --out out --no-plot 2>err.txt";
    const int raw = std::system(command.c_str());
    ASSERT_TRUE(WIFEXITED(raw));
    EXPECT_EQ(WEXITSTATUS(raw), 2) << prefix;
    const std::string err = mresim::testing::read_text(dir / "err.txt");
    EXPECT_TRUE(starts_with(err, prefix)) << err;
    EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
    for (const auto& entry : std::filesystem::directory_iterator(dir.path())) {
      const std::string name = entry.path().filename().string();
      EXPECT_TRUE(name == "bad.toml" || name == "err.txt") << "left behind: " << name;
    }
  }
}

// Fig. 2.9's first column, S0 = 3.2 um, lies inside the WCA cut-off 2^(1/6) 2R = 3.367 um: the
// penalty pushes the pair out. The run says so (stderr and results.h5 /@warnings).
TEST(PairInputWarnings, RestSeparationInsideTheWcaCutoffIsReported) {
  const std::string text = edit(edit(kLoop, "model = \"single\"\nk = 4e-2",
                                     "model = \"three\"\n"
                                     "shear_modulus = 1375"),
                                "rest_separation = 9e-6", "rest_separation = 3.2e-6");
  const mresim::testing::TempDir dir;
  mresim::testing::write_text(dir / "wca.toml", text);
  const std::string command = "cd '" + dir.path().string() + "' && '" + MRESIM_CLI_PATH +
                              "' run wca.toml --out out --no-plot 2>err.txt >/dev/null";
  const int raw = std::system(command.c_str());
  ASSERT_TRUE(WIFEXITED(raw));
  EXPECT_EQ(WEXITSTATUS(raw), 0);
  const std::string expected =
      "springs.rest_separation = 3.2e-06 m lies inside the WCA cut-off penalty.r_cut = "
      "3.36739e-06 m, where the penalty acts: at zero field the pair sits at S = 3.36739e-06 m "
      "instead of S0 = 3.2e-06 m";
  const std::string err = mresim::testing::read_text(dir / "err.txt");
  EXPECT_NE(err.find("mresim: warning: " + expected + "\n"), std::string::npos) << err;
  const mresim::testing::Hdf5Reader h5(dir / "out" / "results.h5");
  EXPECT_EQ(h5.string_attribute("/", "warnings"), expected);
  // What the warning says is what the solver does: the zero-field state sits there.
  const std::vector<double> distance = h5.doubles("/cases/0/distance");
  ASSERT_FALSE(distance.empty());
  EXPECT_NEAR(distance[0], 3.36739e-6, 1e-11);
}

TEST(PairInputWarnings, MapColumnsInsideTheCutoffAreReportedOnce) {
  const auto plan = [&] {
    ::testing::internal::CaptureStderr();
    auto p = mresim::app::make_plan(TableReader::parse_string(kMap, "map.toml"));
    return ::testing::internal::GetCapturedStderr();
  }();
  EXPECT_EQ(plan,
            "mresim: warning: map.separation_min: 1 of the 2 separations (3.2e-06 m) lies inside "
            "the WCA cut-off penalty.r_cut = 3.36739e-06 m, where the penalty acts: at zero field "
            "the pair sits at S = 3.36739e-06 m instead of S0 = 3.2e-06 m\n");
}

TEST(PairInputWarnings, NoWarningOutsideTheCutoff) {
  ::testing::internal::CaptureStderr();
  (void)mresim::app::make_plan(TableReader::parse_string(kLoop, "run.toml"));
  EXPECT_EQ(::testing::internal::GetCapturedStderr(), "");
}

TEST(PairInputWarnings, ZeroFieldSeparationMatchesTheRelaxedLoop) {
  mresim::pair::PairSystem p;
  p.springs.model = mresim::pair::SpringModel::three;
  p.springs.k12 = 0.037;
  p.springs.k0 = 0.032;
  p.springs.rest_separation = 3.2e-6;
  p.penalty = mresim::pair::OverlapPenalty::wca_default(p.material.radius);
  mresim::pair::SweepOptions sweep;
  sweep.b_max = 0.01;
  sweep.b_step = 0.01;
  const double predicted = mresim::pair::runs::zero_field_separation(p);
  const mresim::pair::HysteresisLoop loop = mresim::pair::run_hysteresis(p, sweep);
  EXPECT_NEAR(loop.states.front().distance(), predicted, 1e-9 * predicted);
  EXPECT_GT(predicted, 3.3e-6);
}

// A state with a NaN energy (what Ms = 1e160 gave before validation refused it, flagged
// converged) is reported by step and quantity and marked invalid.
TEST(PairResultCheck, NonFiniteStatesAreFlaggedByStepAndQuantity) {
  mresim::pair::HysteresisLoop loop;
  loop.states.resize(3);
  for (auto& s : loop.states) {
    s.separation = Eigen::Vector3d(9e-6, 0.0, 0.0);
    s.magnetization.m = Eigen::Vector3d::Zero();
    s.converged = true;
  }
  loop.states[1].field = 0.01;
  loop.states[1].energy.dipole = std::numeric_limits<double>::quiet_NaN();
  mresim::pair::runs::PairSetup setup;
  setup.label = "huge Ms";
  mresim::app::ResultCheck check("non-finite results");
  mresim::pair::runs::check_loop(check, 0, setup, loop);
  EXPECT_TRUE(mresim::pair::runs::state_is_finite(loop.states[0]));
  EXPECT_FALSE(mresim::pair::runs::state_is_finite(loop.states[1]));
  ASSERT_EQ(check.count(), 1u);
  EXPECT_NE(check.message("hint").find("energy at case 0 (huge Ms), step 1 (B = 0.01 T)"),
            std::string::npos)
      << check.message("hint");
  EXPECT_THROW(check.throw_if_any("hint"), mresim::app::InvalidResults);
}

}  // namespace
