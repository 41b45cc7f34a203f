// `--set KEY=VALUE` overrides (config/overrides.hpp): applied to the parsed table before
// validation, so the ordinary checks and messages apply; malformed arguments name the option.

#include "mresim/config/overrides.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "../support/config_error.hpp"
#include "mresim/config/range.hpp"
#include "mresim/config/table_reader.hpp"

namespace mresim::config {
namespace {

namespace fs = std::filesystem;

const char* const kFile =
    "# a comment that only the original keeps\n"
    "[run]\n"
    "type = \"x\"\n"
    "[field]\n"
    "max = 1.0   # T\n"
    "step = 0.01\n"
    "[[case]]\n"
    "label = \"a\"\n"
    "[[case]]\n"
    "label = \"b\"\n";

toml::table overridden(const std::vector<std::string>& overrides) {
  toml::table root = toml::parse(kFile);
  apply_overrides(root, overrides);
  return root;
}

using mresim::testing::config_error_of;

std::string apply_error(const std::string& argument) {
  return config_error_of([&] { (void)overridden({argument}); });
}

TEST(Overrides, ReplaceANumberAsTomlReadsIt) {
  const auto root = overridden({"field.max=0.05", "field.step = 2"});
  EXPECT_EQ(root["field"]["max"].value<double>(), 0.05);
  ASSERT_TRUE(root["field"]["step"].is_integer());  // a TOML integer, as if written so
  EXPECT_EQ(root["field"]["step"].value<std::int64_t>(), 2);
}

TEST(Overrides, QuotedStringsAndBareWordsAreStrings) {
  const auto root = overridden({"run.type=\"quoted\"", "model.profile=seed", "run.title=a b"});
  EXPECT_EQ(root["run"]["type"].value<std::string>(), "quoted");
  EXPECT_EQ(root["model"]["profile"].value<std::string>(), "seed");
  EXPECT_EQ(root["run"]["title"].value<std::string>(), "a b");
  // Valid TOML stays what it is: true is a boolean, 1e-6 a float, not strings.
  const auto typed = overridden({"a.flag=true", "a.small=1e-6"});
  EXPECT_TRUE(typed["a"]["flag"].is_boolean());
  EXPECT_EQ(typed["a"]["small"].value<double>(), 1e-6);
}

TEST(Overrides, ArraysAndInlineTables) {
  const auto root = overridden({"particles.count_per_axis=[1, 1, 2]", "box={size = [1, 2, 3]}"});
  const auto* counts = root["particles"]["count_per_axis"].as_array();
  ASSERT_NE(counts, nullptr);
  ASSERT_EQ(counts->size(), 3U);
  EXPECT_EQ((*counts)[2].value<std::int64_t>(), 2);
  EXPECT_EQ(root["box"]["size"][1].value<std::int64_t>(), 2);
}

TEST(Overrides, MissingTablesAreCreated) {
  const auto root = overridden({"solver.magnetization.tolerance=1e-9"});
  ASSERT_TRUE(root["solver"].is_table());
  ASSERT_TRUE(root["solver"]["magnetization"].is_table());
  EXPECT_EQ(root["solver"]["magnetization"]["tolerance"].value<double>(), 1e-9);
  EXPECT_EQ(root["field"]["max"].value<double>(), 1.0);  // the rest untouched
}

TEST(Overrides, AnIndexReachesIntoAnArray) {
  const auto root = overridden({"case[1].label=changed", "case[0].penalty.type=wca"});
  EXPECT_EQ(root["case"][0]["label"].value<std::string>(), "a");
  EXPECT_EQ(root["case"][1]["label"].value<std::string>(), "changed");
  EXPECT_EQ(root["case"][0]["penalty"]["type"].value<std::string>(), "wca");
  const auto element = overridden({"x=[1, 2, 3]", "x[2]=7"});
  EXPECT_EQ(element["x"][2].value<std::int64_t>(), 7);
}

TEST(Overrides, ALaterOverrideOfTheSameKeyWins) {
  const auto root = overridden({"field.max=0.5", "field.max=0.25"});
  EXPECT_EQ(root["field"]["max"].value<double>(), 0.25);
}

TEST(Overrides, MalformedArgumentsNameTheOptionAndTheArgument) {
  EXPECT_EQ(apply_error("fieldmax"), "--set: fieldmax: expected KEY=VALUE, e.g. field.max=0.5");
  EXPECT_EQ(apply_error("=1"),
            "--set: =1: empty KEY before '='; expected KEY=VALUE, e.g. field.max=0.5");
  EXPECT_EQ(apply_error("field..max=1"),
            "--set: field..max=1: empty part in KEY 'field..max' (a dotted path such as "
            "field.max)");
  EXPECT_EQ(apply_error("field.max="),
            "--set: field.max=: empty VALUE; write \"\" for an empty string");
  EXPECT_EQ(apply_error("field.m x=1")
                .rfind("--set: field.m x=1: 'm x' in KEY 'field.m x' is "
                       "not a bare TOML key",
                       0),
            0U);
  EXPECT_EQ(apply_error("case[x].label=1").rfind("--set: case[x].label=1: 'case[x]' in KEY", 0),
            0U);
  const std::string array = apply_error("field.max=[1,");
  EXPECT_EQ(array.rfind("--set: field.max=[1,: VALUE [1, is not a valid TOML value: ", 0), 0U)
      << array;
  EXPECT_EQ(array.find('\n'), std::string::npos);
  EXPECT_EQ(apply_error("a=1\nb = 2"), "--set: a=1\nb = 2: VALUE 1\nb = 2 is not one TOML value");
  // The syntax check alone, as the command line runs it: the message without the option.
  EXPECT_EQ(override_syntax_error("fieldmax"), "fieldmax: expected KEY=VALUE, e.g. field.max=0.5");
  EXPECT_EQ(override_syntax_error("field.max=0.5"), "");
  EXPECT_EQ(override_syntax_error("field.max.x=1"), "");  // needs the table to be refused
}

TEST(Overrides, AParentThatIsNotATableIsRefused) {
  EXPECT_EQ(apply_error("field.max.x=1"),
            "--set: field.max.x=1: field.max = 1.0 is a float, not a table");
  EXPECT_EQ(apply_error("run.type.x=1"),
            "--set: run.type.x=1: run.type = \"x\" is a string, not a table");
  EXPECT_EQ(apply_error("case[5].label=1"),
            "--set: case[5].label=1: case has 2 entries, so there is no case[5]");
  EXPECT_EQ(apply_error("field[0]=1"), "--set: field[0]=1: field = {...} is a table, not an array");
  EXPECT_EQ(apply_error("nothing[0]=1"), "--set: nothing[0]=1: there is no array nothing to index");
}

TEST(Overrides, TheEffectiveTextReadsBackToTheSameTable) {
  // Every example run file, with and without an override, through toml++'s formatter and back.
  int files = 0;
  for (const auto& e : fs::recursive_directory_iterator(fs::path(MRESIM_SOURCE_DIR) / "examples")) {
    if (e.path().extension() != ".toml") continue;
    ++files;
    toml::table root = toml::parse_file(e.path().string());
    for (int pass = 0; pass < 2; ++pass) {
      const toml::table back = toml::parse(toml_text(root));
      EXPECT_EQ(back, root) << e.path();
      apply_overrides(root, {"field.max=0.123456789012345678", "x.y.z=[0.1, 1e-300, \"s\"]"});
    }
  }
  EXPECT_GT(files, 10);
}

TEST(TableReaderOverrides, RecordTheFileTheOverridesAndTheEffectiveText) {
  const auto root = TableReader::parse_string(kFile, "f.toml", {"field.max=0.5"});
  EXPECT_EQ(root.file_text(), kFile);
  EXPECT_EQ(root.overrides(), std::vector<std::string>{"field.max=0.5"});
  EXPECT_EQ(root.source_name(), "f.toml");
  EXPECT_EQ(root.source_text().find("comment"), std::string::npos);  // toml++'s text
  EXPECT_EQ(TableReader::parse_string(root.source_text(), "again")
                .table("field")
                .number("max", Range::positive(), "T"),
            0.5);
  EXPECT_EQ(root.table("field").number("max", Range::positive(), "T"), 0.5);
  // Without overrides nothing changes: the text is the file, byte for byte.
  const auto plain = TableReader::parse_string(kFile, "f.toml", {});
  EXPECT_EQ(plain.source_text(), kFile);
  EXPECT_EQ(plain.file_text(), kFile);
  EXPECT_TRUE(plain.overrides().empty());
}

TEST(TableReaderOverrides, OverriddenValuesAreValidatedLikeTheFile) {
  const auto root = TableReader::parse_string(kFile, "f.toml", {"field.max=-1"});
  EXPECT_EQ(
      config_error_of([&] { (void)root.table("field").number("max", Range::positive(), "T"); }),
      "field.max = -1: must be > 0 (T)");
  const auto typo = TableReader::parse_string(kFile, "f.toml", {"field.maxx=1"});
  const auto field = typo.table("field");
  (void)field.number("max", Range::positive(), "T");
  (void)field.number("step", Range::positive(), "T");
  (void)typo.table("run").string_or("type", "");
  (void)typo.table_list("case");
  for (const auto& c : typo.table_list("case")) (void)c.string_or("label", "");
  EXPECT_EQ(config_error_of([&] { typo.reject_unknown_keys(); }),
            "unknown key 'field.maxx' in [field]; allowed keys: max, step");
}

}  // namespace
}  // namespace mresim::config
