// Invalid two-dipole run files: each gives one clear line naming the key, the value and what is
// allowed (and, through the command line, exit status 2 with nothing written: see the last test).
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <string>

#include "../support/temp_dir.hpp"
#include "mresim/app/run_type.hpp"

namespace {

using mresim::config::ConfigError;
using mresim::config::TableReader;

const std::string kValid = R"(
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

std::string error_of(const std::string& text) {
  try {
    mresim::app::make_plan(TableReader::parse_string(text, "run.toml"));
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "(no error)";
}

// Replaces the first occurrence of `from` in the valid file.
std::string with(const std::string& from, const std::string& to) {
  std::string text = kValid;
  const auto at = text.find(from);
  if (at == std::string::npos) throw std::logic_error("no " + from);
  return text.replace(at, from.size(), to);
}

TEST(PairRunFile, ValidFileBuildsAPlan) { EXPECT_EQ(error_of(kValid), "(no error)"); }

struct BadInput {
  std::string name;
  std::string text;
  std::string message;
};

// Names the case in test output instead of dumping the struct's bytes.
void PrintTo(const BadInput& input, std::ostream* os) { *os << input.name; }

class PairRunFileErrors : public ::testing::TestWithParam<BadInput> {};

TEST_P(PairRunFileErrors, NameTheKeyTheValueAndWhatIsAllowed) {
  EXPECT_EQ(error_of(GetParam().text), GetParam().message);
}

INSTANTIATE_TEST_SUITE_P(
    TwoDipole, PairRunFileErrors,
    ::testing::Values(
        BadInput{"NegativeStiffness", with("k = 4e-2", "k = -4e-2"),
                 "springs.k = -0.04: must be > 0 (N/m)"},
        BadInput{"SeparationInsideContact",
                 with("rest_separation = 9e-6", "rest_separation = 3e-6"),
                 "springs.rest_separation = 3e-06: must be > 2R = 3e-06 m (the spheres would "
                 "overlap)"},
        BadInput{"NonPositiveSusceptibility", kValid + "[material]\nsusceptibility = 0\n",
                 "material.susceptibility = 0: must be > 0"},
        BadInput{"ZeroFieldStep", with("step = 0.01", "step = 0"),
                 "field.step = 0: must be > 0 (T)"},
        BadInput{"MaxNotAMultipleOfStep", with("max = 1.0", "max = 1.005"),
                 "field.max = 1.005: must be a whole number of field.step = 0.01 T (the sweep "
                 "visits 0, +max, -max exactly)"},
        BadInput{"UnknownKey", with("step = 0.01", "step = 0.01\nstpe = 0.02"),
                 "unknown key 'field.stpe' in [field]; allowed keys: angle, max, step"},
        BadInput{"WrongType", with("k = 4e-2", "k = \"soft\""),
                 "springs.k = \"soft\": expected a number (N/m)"},
        BadInput{"UnknownModel", with("model = \"single\"", "model = \"double\""),
                 "springs.model = \"double\": must be one of single, three"},
        BadInput{"UnknownPenalty", kValid + "[penalty]\ntype = \"tahn\"\n",
                 "penalty.type = \"tahn\": must be one of tanh, wca"},
        BadInput{"TwoStiffnesses", with("k = 4e-2", "k = 4e-2\nshear_modulus = 1375"),
                 "springs.shear_modulus = 1375: give one stiffness: k, k0 and k12, "
                 "shear_modulus or youngs_modulus (also given: k)"},
        BadInput{"ThreeSpringWithSingleK", with("model = \"single\"", "model = \"three\""),
                 "springs.k = 0.04: the three-spring model takes k0 and k12 (or shear_modulus); "
                 "k is the single spring"},
        BadInput{"AngleOutOfRange", with("step = 0.01", "step = 0.01\nangle = 120"),
                 "field.angle = 120: must be in [0, 90] (deg)"},
        BadInput{"NoStiffness", with("k = 4e-2", ""),
                 "springs.model = \"single\": needs a stiffness: k (single), k0 and k12 (three), "
                 "shear_modulus, or youngs_modulus (single)"},
        BadInput{"ToleranceNotBelowStep", kValid + "[critical_fields]\ntolerance = 0.05\n",
                 "critical_fields.tolerance = 0.05: must be < field.step = 0.01 T"},
        BadInput{"UnstableSusceptibility", kValid + "[material]\nsusceptibility = 12\n",
                 "material.susceptibility = 12: must be < 12: above it two touching spheres "
                 "magnetize each other without a field (eq. 2.5 becomes singular)"},
        BadInput{"WcaCutoffBelowMinimum",
                 kValid + "[penalty]\ntype = \"wca\"\nr_min = 3e-6\nr_cut = 2e-6\n",
                 "penalty.r_cut = 2e-06: must be > penalty.r_min = 3e-06 m"},
        BadInput{"CaseWithoutLabel", kValid + "[[case]]\nsprings.k = 0.1\n",
                 "case[0].label = \"\": each [[case]] needs a non-empty label"},
        BadInput{"MapWithoutRows",
                 with("type = \"pair_hysteresis\"", "type = \"pair_map\"") +
                     "[map]\nrows = \"k\"\nrow_min = 1e-3\nrow_max = 1.0\n",
                 "map.row_count = (missing): the row axis needs row_min, row_max and row_count "
                 ">= 1 (or row_values = [...])"},
        BadInput{"EnsembleSeparationInsideContact",
                 with("type = \"pair_hysteresis\"", "type = \"pair_ensemble\"") +
                     "[ensemble]\nseparation_values = [2e-6, 9e-6]\nmean = 5e-6\n"
                     "standard_deviation = 1e-6\n",
                 "ensemble.separation_values = 2e-06: every separation must be > 2R = 3e-06 m "
                 "(the spheres would overlap)"}),
    [](const auto& info) { return info.param.name; });

// Through the command line: exit status 2, the message on stderr, and no output directory.
TEST(PairRunFile, CommandLineRejectsBadInputWithoutWritingAnything) {
  const mresim::testing::TempDir dir;
  mresim::testing::write_text(dir / "bad.toml", with("k = 4e-2", "k = -4e-2"));
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
