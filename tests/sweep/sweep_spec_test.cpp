// The [sweep] table (sweep/sweep_spec.hpp): cartesian products and zipped lists over dotted
// keys, expanded into one set of --set overrides per point; malformed tables refused by name.

#include "mresim/sweep/sweep_spec.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "../support/config_error.hpp"

namespace mresim::sweep {
namespace {

using mresim::testing::config_error_of;
using Strings = std::vector<std::string>;

const std::string kBase =
    "[run]\n"
    "type = \"pair_hysteresis\"\n"
    "[field]\n"
    "max = 1.0\n"
    "angle = 0.0\n";

SweepSpec expand(const std::string& sweep) { return expand_sweep(toml::parse(kBase + sweep)); }

Strings overrides_of(const SweepSpec& spec) {
  Strings all;
  for (const auto& p : spec.points) {
    std::string joined;
    for (const auto& o : p.overrides) joined += (joined.empty() ? "" : " ") + o;
    all.push_back(joined);
  }
  return all;
}

TEST(SweepSpec, ProductTakesEveryCombinationInTheOrderWrittenLastFastest) {
  const SweepSpec spec = expand(
      "[sweep]\n"
      "product = { \"field.max\" = [0.5, 1.0], \"field.angle\" = [0, 45, 90] }\n");
  EXPECT_EQ(spec.keys, (Strings{"field.max", "field.angle"}));
  EXPECT_EQ(overrides_of(spec),
            (Strings{"field.max=0.5 field.angle=0", "field.max=0.5 field.angle=45",
                     "field.max=0.5 field.angle=90", "field.max=1.0 field.angle=0",
                     "field.max=1.0 field.angle=45", "field.max=1.0 field.angle=90"}));
  for (std::size_t i = 0; i < spec.points.size(); ++i) EXPECT_EQ(spec.points[i].index, i);
}

TEST(SweepSpec, ZipPairsItsListsAndIsTheOutermostAxis) {
  const SweepSpec spec = expand(
      "[sweep.zip]\n"
      "\"field.max\" = [0.5, 1.0]\n"
      "\"run.title\" = [\"low\", \"high\"]\n"
      "[sweep.product]\n"
      "\"field.angle\" = [0, 90]\n");
  EXPECT_EQ(spec.keys, (Strings{"field.max", "run.title", "field.angle"}));
  EXPECT_EQ(overrides_of(spec), (Strings{"field.max=0.5 run.title=\"low\" field.angle=0",
                                         "field.max=0.5 run.title=\"low\" field.angle=90",
                                         "field.max=1.0 run.title=\"high\" field.angle=0",
                                         "field.max=1.0 run.title=\"high\" field.angle=90"}));
  EXPECT_EQ(spec.points[2].values, (Strings{"1.0", "\"high\"", "0"}));
}

TEST(SweepSpec, DottedKeysOfNestedTablesNameTheSameKeysAsQuotedOnes) {
  const SweepSpec spec = expand(
      "[sweep.product]\n"
      "field.max = [0.25, 0.5]\n"
      "\"case[1].label\" = [\"a\"]\n");
  EXPECT_EQ(spec.keys, (Strings{"field.max", "case[1].label"}));
  EXPECT_EQ(spec.points.size(), 2U);
}

TEST(SweepSpec, TheBaseIsTheRunFileWithoutSweepAndValuesKeepTheirTypes) {
  const SweepSpec spec = expand(
      "[sweep]\n"
      "product = { \"particles.count_per_axis\" = [[1, 1, 2]], \"field.max\" = [1e-3, 2] }\n");
  const toml::table base = toml::parse(spec.base_text);
  EXPECT_FALSE(base.contains("sweep"));
  EXPECT_EQ(base["field"]["max"].value<double>(), 1.0);
  EXPECT_EQ(spec.points[0].values, (Strings{"[1, 1, 2]", "0.001"}));
  EXPECT_EQ(spec.points[1].values, (Strings{"[1, 1, 2]", "2"}));
}

TEST(SweepSpec, RefusesZipListsOfDifferentLengths) {
  EXPECT_EQ(
      config_error_of([] {
        (void)expand("[sweep]\nzip = { \"field.max\" = [0.5, 1.0], \"field.angle\" = [0] }\n");
      }),
      "sweep.zip: the lists must have one length: \"field.max\" has 2 value(s), "
      "\"field.angle\" has 1");
}

TEST(SweepSpec, RefusesUnknownKeysOfTheSweepTable) {
  EXPECT_EQ(config_error_of([] { (void)expand("[sweep]\nprodcut = { \"field.max\" = [1] }\n"); }),
            "unknown key 'sweep.prodcut' in [sweep]; allowed keys: product, zip");
}

TEST(SweepSpec, RefusesAValueThatIsNotAList) {
  EXPECT_EQ(config_error_of([] { (void)expand("[sweep]\nproduct = { \"field.max\" = 0.5 }\n"); }),
            "sweep.product.\"field.max\" = 0.5: must be a non-empty list of the values to sweep, "
            "e.g. [0.1, 0.2]");
  EXPECT_EQ(config_error_of([] { (void)expand("[sweep]\nproduct = { \"field.max\" = [] }\n"); }),
            "sweep.product.\"field.max\" = []: must be a non-empty list of the values to sweep, "
            "e.g. [0.1, 0.2]");
}

TEST(SweepSpec, RefusesAKeyThatIsNotASetKey) {
  const std::string message =
      config_error_of([] { (void)expand("[sweep]\nproduct = { \"field..max\" = [1] }\n"); });
  EXPECT_NE(message.find("sweep.product.\"field..max\": not a valid key: empty part in KEY"),
            std::string::npos)
      << message;
}

TEST(SweepSpec, RefusesAKeySweptTwiceAndAnEmptySweep) {
  EXPECT_EQ(
      config_error_of([] {
        (void)expand("[sweep]\nzip = { \"field.max\" = [1] }\nproduct = { \"field.max\" = [2] }\n");
      }),
      "sweep: \"field.max\" is swept twice (in both zip and product); name each key once");
  EXPECT_EQ(config_error_of([] { (void)expand("[sweep]\n"); }),
            "[sweep] sweeps nothing: give product = {...} and/or zip = {...}");
  EXPECT_EQ(config_error_of([] { (void)expand("sweep = 3\n"); }),
            "sweep: must be a table: [sweep] with product = {...} and/or zip = {...}");
}

TEST(SweepSpec, ValueTextIsShortAndReadsBackAsTheSameValue) {
  const toml::table t = toml::parse(
      "a = 0.05\nb = 3\nc = 1e300\nd = \"x\\\"y\"\ne = true\nf = { size = [1.0, 2] }\ng = 2.0\n");
  EXPECT_EQ(toml_value_text(*t.get("a")), "0.05");
  EXPECT_EQ(toml_value_text(*t.get("b")), "3");
  EXPECT_EQ(toml_value_text(*t.get("c")), "1e+300");
  EXPECT_EQ(toml_value_text(*t.get("d")), "\"x\\\"y\"");
  EXPECT_EQ(toml_value_text(*t.get("e")), "true");
  EXPECT_EQ(toml_value_text(*t.get("f")), "{size = [1.0, 2]}");
  EXPECT_EQ(toml_value_text(*t.get("g")), "2.0");
  const toml::table back = toml::parse("v = " + toml_value_text(*t.get("c")));
  EXPECT_EQ(back["v"].value<double>(), 1e300);
}

}  // namespace
}  // namespace mresim::sweep
