#include "mresim/config/table_reader.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <string>

#include "../support/config_error.hpp"
#include "../support/toml_text.hpp"

namespace mresim::config {
namespace {

using mresim::testing::config_error_of;
using mresim::testing::parse;

TEST(TableReaderNumber, AcceptsIntegersAndFloats) {
  const auto root = parse("[model]\nk = 0.04\nn = 3\n");
  const auto model = root.table("model");
  EXPECT_DOUBLE_EQ(model.number("k", Range::positive(), "N/m"), 0.04);
  EXPECT_DOUBLE_EQ(model.number("n", Range::positive(), ""), 3.0);
}

TEST(TableReaderNumber, ReportsMissingKeyWithUnit) {
  const auto model = parse("[model]\nR = 1.5e-6\n").table("model");
  EXPECT_EQ(config_error_of([&] { (void)model.number("k", Range::positive(), "N/m"); }),
            "missing key 'model.k' (N/m)");
  EXPECT_EQ(config_error_of([&] { (void)model.number("S0", Range::positive(), ""); }),
            "missing key 'model.S0'");
}

TEST(TableReaderNumber, ReportsWrongType) {
  const auto model = parse("[model]\nk = \"abc\"\nb = true\nl = [1, 2]\n").table("model");
  EXPECT_EQ(config_error_of([&] { (void)model.number("k", Range::positive(), "N/m"); }),
            "model.k = \"abc\": expected a number (N/m)");
  EXPECT_EQ(config_error_of([&] { (void)model.number("b", Range::any(), ""); }),
            "model.b = true: expected a number");
  EXPECT_EQ(config_error_of([&] { (void)model.number("l", Range::any(), "m"); }),
            "model.l = [1, 2]: expected a number (m)");
}

TEST(TableReaderNumber, ReportsOutOfRange) {
  const auto model = parse("[model]\nk = -0.04\nangle = 95\nS0 = 2e-6\n").table("model");
  EXPECT_EQ(config_error_of([&] { (void)model.number("k", Range::positive(), "N/m"); }),
            "model.k = -0.04: must be > 0 (N/m)");
  EXPECT_EQ(config_error_of([&] { (void)model.number("angle", Range::between(0, 90), "deg"); }),
            "model.angle = 95: must be in [0, 90] (deg)");
  EXPECT_EQ(config_error_of([&] { (void)model.number("S0", Range::at_least(3e-6), "m"); }),
            "model.S0 = 2e-06: must be >= 3e-06 (m)");
}

TEST(TableReaderNumber, RejectsNanAndInfinity) {
  const auto model = parse("[model]\na = nan\nb = -inf\n").table("model");
  EXPECT_EQ(config_error_of([&] { (void)model.number("a", Range::any(), "T"); }),
            "model.a = nan: expected a finite number (T)");
  EXPECT_EQ(config_error_of([&] { (void)model.number("b", Range::any(), ""); }),
            "model.b = -inf: expected a finite number");
}

TEST(TableReaderNumber, FallbackAndOptional) {
  const auto model = parse("[model]\nk = 2\n").table("model");
  EXPECT_DOUBLE_EQ(model.number_or("k", 1.0, Range::positive(), ""), 2.0);
  EXPECT_DOUBLE_EQ(model.number_or("absent", 1.5, Range::positive(), ""), 1.5);
  EXPECT_FALSE(model.optional_number("other", Range::any(), "").has_value());
  EXPECT_EQ(config_error_of([&] { (void)model.number_or("k", 1.0, Range::above(5), "N/m"); }),
            "model.k = 2: must be > 5 (N/m)");
}

TEST(TableReaderInteger, AcceptsIntegersRejectsFloats) {
  const auto field =
      parse("[field]\ncount = 2.5\nsteps = 10\nneg = -1\nwhole = 2.0\n").table("field");
  EXPECT_EQ(field.integer("steps", Range::at_least(1)), 10);
  EXPECT_EQ(config_error_of([&] { (void)field.integer("count", Range::any()); }),
            "field.count = 2.5: expected an integer");
  EXPECT_EQ(config_error_of([&] { (void)field.integer("whole", Range::any()); }),
            "field.whole = 2.0: expected an integer");
  EXPECT_EQ(config_error_of([&] { (void)field.integer("neg", Range::non_negative()); }),
            "field.neg = -1: must be >= 0");
  EXPECT_EQ(config_error_of([&] { (void)field.integer("absent", Range::any()); }),
            "missing key 'field.absent'");
  EXPECT_EQ(field.integer_or("absent", 7, Range::any()), 7);
  EXPECT_EQ(field.integer_or("steps", 7, Range::any()), 10);
}

TEST(TableReaderScalars, BooleanAndString) {
  const auto run = parse("[run]\nflag = true\nbad = 1\ntitle = \"x\"\nnum = 3\n").table("run");
  EXPECT_TRUE(run.boolean_or("flag", false));
  EXPECT_TRUE(run.boolean_or("absent", true));
  EXPECT_EQ(config_error_of([&] { (void)run.boolean_or("bad", false); }),
            "run.bad = 1: expected true or false");
  EXPECT_EQ(run.string_or("title", "y"), "x");
  EXPECT_EQ(run.string_or("absent", "y"), "y");
  EXPECT_EQ(config_error_of([&] { (void)run.string_or("num", ""); }),
            "run.num = 3: expected a string");
}

TEST(TableReaderChoice, ListsAllowedValues) {
  const auto penalty =
      parse("[penalty]\ntype = \"tahn\"\nnum = 3\nok = \"wca\"\n").table("penalty");
  const std::vector<std::string> allowed{"tanh", "wca"};
  EXPECT_EQ(config_error_of([&] { (void)penalty.choice("type", allowed); }),
            "penalty.type = \"tahn\": must be one of tanh, wca");
  EXPECT_EQ(config_error_of([&] { (void)penalty.choice("num", allowed); }),
            "penalty.num = 3: expected a string, one of tanh, wca");
  EXPECT_EQ(config_error_of([&] { (void)penalty.choice("absent", allowed); }),
            "missing key 'penalty.absent' (one of tanh, wca)");
  EXPECT_EQ(penalty.choice("ok", allowed), "wca");
  EXPECT_EQ(penalty.choice_or("absent", "tanh", allowed), "tanh");
}

TEST(TableReaderList, ChecksTypeSizeAndEachElement) {
  const auto field = parse(
                         "[field]\nvalues = [0, 0.5, 1]\nshort = [1]\nbad = [1, \"a\"]\n"
                         "neg = [1, -1]\nscalar = 3\n")
                         .table("field");
  EXPECT_EQ(field.number_list("values", Range::non_negative(), "T", 2),
            (std::vector<double>{0, 0.5, 1}));
  EXPECT_EQ(config_error_of([&] { (void)field.number_list("short", Range::any(), "T", 2); }),
            "field.short = [1]: expected at least 2 values (T)");
  EXPECT_EQ(config_error_of([&] { (void)field.number_list("bad", Range::any(), "T"); }),
            "field.bad[1] = \"a\": expected a number (T)");
  EXPECT_EQ(config_error_of([&] { (void)field.number_list("neg", Range::non_negative(), "T"); }),
            "field.neg[1] = -1: must be >= 0 (T)");
  EXPECT_EQ(config_error_of([&] { (void)field.number_list("scalar", Range::any(), "T"); }),
            "field.scalar = 3: expected a list of numbers (T)");
  EXPECT_EQ(config_error_of([&] { (void)field.number_list("absent", Range::any(), "T"); }),
            "missing key 'field.absent' (T)");
  EXPECT_FALSE(field.optional_number_list("absent", Range::any(), "T").has_value());
}

TEST(TableReaderTables, RequiredOptionalAndNested) {
  const auto root = parse("[model]\n[model.penalty]\nwidth = 1\n[other]\nx = 1\nscalar = 2\n");
  EXPECT_EQ(config_error_of([&] { (void)root.table("field"); }), "missing table [field]");
  EXPECT_FALSE(root.optional_table("field").has_value());
  const auto penalty = root.table("model").table("penalty");
  EXPECT_EQ(penalty.path(), "model.penalty");
  EXPECT_EQ(penalty.path("width"), "model.penalty.width");
  EXPECT_EQ(config_error_of([&] { (void)penalty.table("deeper"); }),
            "missing table [model.penalty.deeper]");
  EXPECT_EQ(config_error_of([&] { (void)root.table("other").table("x"); }),
            "other.x = 1: expected a table [other.x]");
  EXPECT_TRUE(root.has("model"));
  EXPECT_FALSE(root.has("field"));
}

TEST(TableReaderTables, ArrayOfTables) {
  const auto root = parse("[[sweep]]\nk = 1\n[[sweep]]\nk = -2\n");
  const auto sweeps = root.table_list("sweep");
  ASSERT_EQ(sweeps.size(), 2U);
  EXPECT_DOUBLE_EQ(sweeps[0].number("k", Range::positive(), ""), 1.0);
  EXPECT_EQ(config_error_of([&] { (void)sweeps[1].number("k", Range::positive(), "N/m"); }),
            "sweep[1].k = -2: must be > 0 (N/m)");
  EXPECT_TRUE(root.table_list("absent").empty());
  const auto scalar = parse("sweep = 3\n");
  EXPECT_EQ(config_error_of([&] { (void)scalar.table_list("sweep"); }),
            "sweep = 3: expected an array of tables [[sweep]]");
}

TEST(TableReaderFail, CrossKeyErrorsUseTheCommonFormat) {
  const auto model = parse("[model]\nS0 = 2e-6\nR = 1.5e-6\n").table("model");
  EXPECT_EQ(config_error_of([&] { model.fail("S0", 2e-6, "must be > 2R = 3e-06 m"); }),
            "model.S0 = 2e-06: must be > 2R = 3e-06 m");
  EXPECT_EQ(config_error_of([&] { model.fail("S0", model.value_text("S0"), "must be > 2R"); }),
            "model.S0 = 2e-06: must be > 2R");
  EXPECT_EQ(model.value_text("absent"), "");
}

TEST(TableReaderTypos, MissingKeyPointsAtTheLikelyMisspelling) {
  const auto root = parse("[fiedl]\nmax = 1\n[field]\nstpe = 0.1\n");
  EXPECT_EQ(
      config_error_of([&] { (void)root.table("field").number("step", Range::positive(), "T"); }),
      "missing key 'field.step' (T); the file has 'field.stpe' - a misspelling?");
  const auto other = parse("[fiedl]\nmax = 1\n[run]\n");
  EXPECT_EQ(config_error_of([&] { (void)other.table("field"); }),
            "missing table [field]; the file has [fiedl] - a misspelling?");
  // Too far from any key in the file: no guess.
  EXPECT_EQ(config_error_of([&] { (void)other.table("model"); }), "missing table [model]");
}

TEST(TableReaderSource, KeepsTheRawText) {
  const std::string text = "# comment kept\n[run]\ntype = \"x\"\n";
  const auto root = TableReader::parse_string(text, "memo.toml");
  EXPECT_EQ(root.source_text(), text);
  EXPECT_EQ(root.source_name(), "memo.toml");
}

TEST(TableReaderParse, SyntaxErrorNamesFileLineAndColumn) {
  const std::string message = config_error_of([] { (void)parse("[run]\ntype = \n"); });
  EXPECT_EQ(message.rfind("test.toml:2:8: TOML syntax error: ", 0), 0U) << message;
}

// Found by the run-file fuzzer: the parser quotes the input up to the next line break.
TEST(TableReaderParse, SyntaxErrorIsOneLineEvenWhenTheParserQuotesALineBreak) {
  const std::string message = config_error_of([] { (void)parse("[model]\nflag = fal\nx = 1\n"); });
  EXPECT_EQ(message.rfind("test.toml:2:", 0), 0U) << message;
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  EXPECT_NE(message.find("expected 'false'"), std::string::npos) << message;
}

TEST(TableReaderParse, MissingFile) {
  EXPECT_EQ(config_error_of([] { (void)TableReader::parse_file("/nonexistent/run.toml"); }),
            "cannot read run file '/nonexistent/run.toml': No such file or directory");
  EXPECT_EQ(config_error_of([] { (void)TableReader::parse_file("/"); }),
            "cannot read run file '/': it is a directory");
}

TEST(TableReaderParse, ReadsAFile) {
  const auto file = std::filesystem::temp_directory_path() /
                    ("mresim_reader_" + std::to_string(::getpid()) + ".toml");
  std::ofstream(file) << "[run]\ntype = \"x\"\n";
  const auto root = TableReader::parse_file(file);
  EXPECT_EQ(root.table("run").string_or("type", ""), "x");
  EXPECT_EQ(root.source_name(), file.string());
  std::filesystem::remove(file);
}

}  // namespace
}  // namespace mresim::config
