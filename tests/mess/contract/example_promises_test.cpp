// The small Chapter 4 examples keep the promises of their headers ("Expect: ..."): each
// examples/chapter4/small/<name>.toml has tests/data/examples/<name>.json stating those promises
// as checks (format: tests/data/examples/README.md), and one test per data file runs the example
// through `mresim run` and checks every promise against its results.h5.
//
// The runs take 1-15 s each on one thread; the data files marked "slow" are instantiated as
// SlowExamplePromises/..., which the sanitizer stage (.ci/sanitize) leaves out.

#include "example_promises.hpp"

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "../../support/json_file.hpp"
#include "../../support/temp_dir.hpp"

namespace {

namespace fs = std::filesystem;
namespace pr = mresim::testing::promises;
using mresim::testing::read_json;
using nlohmann::json;

const fs::path kSource = MRESIM_SOURCE_DIR;
const fs::path kDataDir = kSource / "tests/data/examples";
const fs::path kExampleDir = kSource / "examples/chapter4/small";

// The data files' stems, those marked "slow" or the others.
std::vector<std::string> data_files(bool slow) {
  std::vector<std::string> out;
  if (!fs::is_directory(kDataDir)) return out;
  for (const auto& e : fs::directory_iterator(kDataDir)) {
    if (e.path().extension() != ".json") continue;
    if (read_json(e.path()).value("slow", false) == slow) out.push_back(e.path().stem().string());
  }
  std::sort(out.begin(), out.end());
  return out;
}

int run_example(const fs::path& example, const fs::path& out, int threads) {
  const std::string command = std::string("'") + MRESIM_CLI_PATH + "' run '" + example.string() +
                              "' --out '" + out.string() + "' --no-plot -j " +
                              std::to_string(threads) + " >'" + out.string() + ".log' 2>&1";
  const int raw = std::system(command.c_str());
  return WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
}

class ExamplePromises : public ::testing::TestWithParam<std::string> {};

TEST_P(ExamplePromises, HeaderPromisesHold) {
  const json data = read_json(kDataDir / (GetParam() + ".json"));
  const fs::path example = kSource / data.at("example").get<std::string>();
  ASSERT_TRUE(fs::exists(example)) << example;
  const mresim::testing::TempDir dir;
  fs::path out = dir / "run";
  // MRESIM_EXAMPLE_RESULTS=DIR checks DIR/<name>/results.h5 of earlier runs instead of running.
  if (const char* earlier = std::getenv("MRESIM_EXAMPLE_RESULTS"); earlier != nullptr) {
    out = fs::path(earlier) / GetParam();
  } else {
    ASSERT_EQ(run_example(example, out, data.value("threads", 1)), 0)
        << mresim::testing::read_text(out.string() + ".log");
  }
  const pr::RunData run = pr::read_run(out / "results.h5");
  ASSERT_FALSE(data.at("checks").empty());
  for (const auto& check : data.at("checks")) {
    for (const auto& failure : pr::evaluate(run, check)) ADD_FAILURE() << failure;
  }
}

std::string name_of(const ::testing::TestParamInfo<std::string>& info) { return info.param; }

INSTANTIATE_TEST_SUITE_P(ExamplePromises, ExamplePromises, ::testing::ValuesIn(data_files(false)),
                         name_of);
INSTANTIATE_TEST_SUITE_P(SlowExamplePromises, ExamplePromises,
                         ::testing::ValuesIn(data_files(true)), name_of);

// Every small example states its promises in a data file, and every data file names an
// existing example: a new example without checks, or a renamed one, fails here.
TEST(ExamplePromiseFiles, OneDataFilePerSmallExample) {
  std::vector<std::string> examples;
  for (const auto& e : fs::directory_iterator(kExampleDir)) {
    if (e.path().extension() == ".toml") examples.push_back(e.path().stem().string());
  }
  std::sort(examples.begin(), examples.end());
  auto files = data_files(false);
  const auto slow = data_files(true);
  files.insert(files.end(), slow.begin(), slow.end());
  std::sort(files.begin(), files.end());
  EXPECT_EQ(files, examples);
  for (const auto& f : files) {
    const json data = read_json(kDataDir / (f + ".json"));
    EXPECT_EQ(data.at("example").get<std::string>(), "examples/chapter4/small/" + f + ".toml");
    for (const auto& check : data.at("checks")) {
      EXPECT_TRUE(check.contains("claim") && check.contains("why")) << f << ": " << check.dump();
    }
  }
}

// The evaluator itself, on a made-up hysteresis run: a loop 0 -> 20 -> -20 -> 20 mT.
pr::RunData made_up_run() {
  pr::RunData r;
  r.field_mT = {0, 20, 0, -20, 0, 20};
  r.load = std::vector<double>(6, 0.0);
  r.separation_um = {6.0, 5.0, 3.4, 3.4, 3.4, 3.4};
  r.m_along_ms = {0.0, 0.5, 0.4, -0.5, -0.4, 0.5};
  r.wca_energy_j = std::vector<double>(6, 0.0);
  r.cluster_count = {2, 2, 1, 1, 1, 1};
  r.largest_cluster = {1, 1, 2, 2, 2, 2};
  r.converged = r.valid = std::vector<std::int64_t>(6, 1);
  r.cluster_id = {{0, 1}, {0, 1}, {0, 0}, {0, 0}, {0, 0}, {0, 0}};
  r.displacement_um = std::vector<std::vector<double>>(6, std::vector<double>(6, 0.0));
  r.displacement_um[1][5] = -0.5;
  r.leg = pr::field_legs(r.field_mT);
  return r;
}

TEST(ExamplePromiseEvaluator, LegsSplitAtTheTurningPoints) {
  EXPECT_EQ(pr::field_legs({0, 20, 0, -20, 0, 20}), (std::vector<int>{0, 0, 1, 1, 2, 2}));
  EXPECT_EQ(pr::field_legs({0, 40, 80, 0, 40, 80}), (std::vector<int>{0, 0, 0, 1, 2, 2}));
}

TEST(ExamplePromiseEvaluator, TrueClaimsPassAndFalseOnesFail) {
  const pr::RunData r = made_up_run();
  const auto check = [&](const char* text) { return pr::evaluate(r, json::parse(text)).size(); };
  EXPECT_EQ(check(R"({"quantity":"M_along_Ms","at":{"leg":1,"B_mT":0},"min":0.3})"), 0U);
  EXPECT_EQ(check(R"({"quantity":"M_along_Ms","at":{"leg":1,"B_mT":0},"max":0.3})"), 1U);
  EXPECT_EQ(check(R"({"quantity":"largest_cluster","at":{"B_nonzero":true},"equals":2})"), 1U);
  EXPECT_EQ(check(R"({"quantity":"largest_cluster","at":{"leg":2},"equals":2})"), 0U);
  EXPECT_EQ(check(R"({"quantity":"pair_clusters","at":{"step":2},"equals":1})"), 0U);
  EXPECT_EQ(check(R"({"quantity":"separation_um","at":{"step":1},"minus":{"step":0},
                      "min":-1.01,"max":-0.99})"),
            0U);
  EXPECT_EQ(check(R"({"quantity":"centre_displacement_um","particle":1,"axis":"z",
                      "at":{"step":1},"max":-0.4})"),
            0U);
  EXPECT_EQ(check(R"({"quantity":"M_along_Ms","at":{"step":1},"plus":{"step":3},
                      "min":-1e-12,"max":1e-12})"),
            0U);
  EXPECT_EQ(check(R"({"quantity":"M_along_Ms","at":{"step":1},"minus":{"step":3},
                      "min":-1e-12,"max":1e-12})"),
            1U);
  // A selector that picks nothing is a failure, not a pass.
  EXPECT_EQ(check(R"({"quantity":"M_along_Ms","at":{"leg":0,"B_mT":-20},"min":0})"), 1U);
  // A strain-run quantity on a run without modulus fits is a failure.
  EXPECT_EQ(check(R"({"quantity":"modulus_kPa","at":{"B_mT":0},"min":0})"), 1U);
  EXPECT_THROW(check(R"({"quantity":"no_such","at":{},"min":0})"), std::runtime_error);
  EXPECT_THROW(check(R"({"quantity":"M_along_Ms","at":{"bogus":1},"min":0})"), std::runtime_error);
}

}  // namespace
