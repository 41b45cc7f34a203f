// Invalid two-dipole run files: each gives one clear line naming the key, the value and what is
// allowed (and, through the command line, exit status 2 with nothing written: see the last test).
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <string>

#include "../support/run_file_edits.hpp"
#include "../support/run_plan.hpp"
#include "../support/temp_dir.hpp"
#include "mresim/app/run_type.hpp"

namespace {

using mresim::testing::BadInput;
using mresim::testing::edit;
using mresim::testing::run_file_error_of;

const std::string kValidPairRun = R"(
[run]
type = "pair_hysteresis"
[springs]
model = "single"
k = 4e-2
rest_separation = 9e-6
[field]
max = 1.0
step = 0.01
)";

// The valid file with the first occurrence of `from` replaced by `to`.
std::string pair_run_with(const std::string& from, const std::string& to) {
  return edit(kValidPairRun, from, to);
}

TEST(PairRunFile, ValidFileBuildsAPlan) {
  EXPECT_EQ(run_file_error_of(kValidPairRun), "(no error)");
}

class PairRunFileErrors : public ::testing::TestWithParam<BadInput> {};

TEST_P(PairRunFileErrors, NameTheKeyTheValueAndWhatIsAllowed) {
  EXPECT_EQ(run_file_error_of(GetParam().text), GetParam().message);
}

INSTANTIATE_TEST_SUITE_P(
    TwoDipole, PairRunFileErrors,
    ::testing::Values(
        BadInput{"NegativeStiffness", pair_run_with("k = 4e-2", "k = -4e-2"),
                 "springs.k = -0.04: must be > 0 (N/m)"},
        BadInput{"SeparationInsideContact",
                 pair_run_with("rest_separation = 9e-6", "rest_separation = 3e-6"),
                 "springs.rest_separation = 3e-06: must be > 2R = 3e-06 m (the spheres would "
                 "overlap)"},
        BadInput{"NonPositiveSusceptibility", kValidPairRun + "[material]\nsusceptibility = 0\n",
                 "material.susceptibility = 0: must be > 0"},
        BadInput{"ZeroFieldStep", pair_run_with("step = 0.01", "step = 0"),
                 "field.step = 0: must be > 0 (T)"},
        BadInput{"MaxNotAMultipleOfStep", pair_run_with("max = 1.0", "max = 1.005"),
                 "field.max = 1.005: must be a whole number of field.step = 0.01 T (the sweep "
                 "visits 0, +max, -max exactly)"},
        BadInput{"UnknownKey", pair_run_with("step = 0.01", "step = 0.01\nstpe = 0.02"),
                 "unknown key 'field.stpe' in [field]; allowed keys: angle, max, step"},
        BadInput{"WrongType", pair_run_with("k = 4e-2", "k = \"soft\""),
                 "springs.k = \"soft\": expected a number (N/m)"},
        BadInput{"UnknownModel", pair_run_with("model = \"single\"", "model = \"double\""),
                 "springs.model = \"double\": must be one of single, three"},
        BadInput{"UnknownPenalty", kValidPairRun + "[penalty]\ntype = \"tahn\"\n",
                 "penalty.type = \"tahn\": must be one of tanh, wca"},
        BadInput{"TwoStiffnesses", pair_run_with("k = 4e-2", "k = 4e-2\nshear_modulus = 1375"),
                 "springs.shear_modulus = 1375: give one stiffness: k, k0 and k12, "
                 "shear_modulus or youngs_modulus (also given: k)"},
        BadInput{"ThreeSpringWithSingleK", pair_run_with("model = \"single\"", "model = \"three\""),
                 "springs.k = 0.04: the three-spring model takes k0 and k12 (or shear_modulus); "
                 "k is the single spring"},
        BadInput{"AngleOutOfRange", pair_run_with("step = 0.01", "step = 0.01\nangle = 120"),
                 "field.angle = 120: must be in [0, 90] (deg)"},
        BadInput{"NoStiffness", pair_run_with("k = 4e-2", ""),
                 "springs.model = \"single\": needs a stiffness: k (single), k0 and k12 (three), "
                 "shear_modulus, or youngs_modulus (single)"},
        BadInput{"ToleranceNotBelowStep", kValidPairRun + "[critical_fields]\ntolerance = 0.05\n",
                 "critical_fields.tolerance = 0.05: must be < field.step = 0.01 T"},
        BadInput{"UnstableSusceptibility", kValidPairRun + "[material]\nsusceptibility = 12\n",
                 "material.susceptibility = 12: must be < 12: above it two touching spheres "
                 "magnetize each other without a field (eq. 2.5 becomes singular)"},
        BadInput{"WcaCutoffBelowMinimum",
                 kValidPairRun + "[penalty]\ntype = \"wca\"\nr_min = 3e-6\nr_cut = 2e-6\n",
                 "penalty.r_cut = 2e-06: must be > penalty.r_min = 3e-06 m"},
        BadInput{"CaseWithoutLabel", kValidPairRun + "[[case]]\nsprings.k = 0.1\n",
                 "case[0].label = \"\": each [[case]] needs a non-empty label"},
        BadInput{"MapWithoutRows",
                 pair_run_with("type = \"pair_hysteresis\"", "type = \"pair_map\"") +
                     "[map]\nrows = \"k\"\nrow_min = 1e-3\nrow_max = 1.0\n",
                 "map.row_count = (missing): the row axis needs row_min, row_max and row_count "
                 ">= 1 (or row_values = [...])"},
        BadInput{"EnsembleSeparationInsideContact",
                 pair_run_with("type = \"pair_hysteresis\"", "type = \"pair_ensemble\"") +
                     "[ensemble]\nseparation_values = [2e-6, 9e-6]\nmean = 5e-6\n"
                     "standard_deviation = 1e-6\n",
                 "ensemble.separation_values = 2e-06: every separation must be > 2R = 3e-06 m "
                 "(the spheres would overlap)"}),
    [](const auto& info) { return info.param.name; });

// Through the command line: exit status 2, the message on stderr, and no output directory.
TEST(PairRunFile, CommandLineRejectsBadInputWithoutWritingAnything) {
  const mresim::testing::TempDir dir;
  mresim::testing::write_text(dir / "bad.toml", pair_run_with("k = 4e-2", "k = -4e-2"));
  const std::string command = "cd '" + dir.path().string() + "' && '" + MRESIM_CLI_PATH +
                              "' run bad.toml --out out --no-plot 2>err.txt";
  const int raw = std::system(command.c_str());
  ASSERT_TRUE(WIFEXITED(raw));
  EXPECT_EQ(WEXITSTATUS(raw), 2);
  EXPECT_EQ(mresim::testing::read_text(dir / "err.txt"),
            "mresim: error: springs.k = -0.04: must be > 0 (N/m)\n");
  EXPECT_FALSE(std::filesystem::exists(dir / "out"));
  EXPECT_FALSE(std::filesystem::exists(dir / "bad"));
}

}  // namespace
