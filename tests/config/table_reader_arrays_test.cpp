// The array, vector and enumeration getters of config::TableReader: values read, and each error
// message (one line naming the key path, the value as written and what is allowed).
#include <gtest/gtest.h>

#include <array>
#include <functional>
#include <string>
#include <vector>

#include "../support/config_error.hpp"
#include "../support/toml_text.hpp"
#include "mresim/config/table_reader.hpp"

namespace mresim::config {
namespace {

using mresim::testing::config_error_of;
using mresim::testing::parse;

// The message of reject_unknown_keys() on `root`, or "" when every key was asked for.
std::string unknown_of(const TableReader& root) {
  try {
    root.reject_unknown_keys();
  } catch (const ConfigError& e) {
    return e.what();
  }
  return {};
}

using Vector = std::array<double, 3>;

TEST(TableReaderVector3, ReadsIntegersAndFloats) {
  const auto box = parse("[box]\nsize = [6e-6, 6, 1.5e-5]\n").table("box");
  EXPECT_EQ(box.optional_vector3("size", Range::positive(), "m"), (Vector{6e-6, 6.0, 1.5e-5}));
  EXPECT_FALSE(box.optional_vector3("centre", Range::any(), "m").has_value());
}

TEST(TableReaderVector3, ReportsShapeTypeAndRange) {
  const auto box = parse(
                       "[box]\nscalar = 3\ntwo = [1, 2]\nfour = [1, 2, 3, 4]\n"
                       "words = [\"9 um\", \"9 um\", \"14 um\"]\nnan = [1, nan, 2]\n"
                       "negative = [1, -2, 3]\ntable = {x = 1}\n")
                       .table("box");
  const auto read = [&](const char* key, std::string_view unit) {
    return [&box, key, unit] { (void)box.optional_vector3(key, Range::positive(), unit); };
  };
  EXPECT_EQ(config_error_of(read("scalar", "m")), "box.scalar = 3: expected [x, y, z] (m)");
  EXPECT_EQ(config_error_of(read("two", "m")), "box.two = [1, 2]: expected [x, y, z] (m)");
  EXPECT_EQ(config_error_of(read("four", "")), "box.four = [1, 2, 3, 4]: expected [x, y, z]");
  EXPECT_EQ(config_error_of(read("table", "m")), "box.table = {...}: expected [x, y, z] (m)");
  EXPECT_EQ(config_error_of(read("words", "m")), "box.words[0] = \"9 um\": expected a number (m)");
  EXPECT_EQ(config_error_of(read("nan", "m")), "box.nan[1] = nan: expected a finite number (m)");
  EXPECT_EQ(config_error_of(read("negative", "m")), "box.negative[1] = -2: must be > 0 (m)");
}

// The value in a message is written as elsewhere in the reader: strings escaped.
TEST(TableReaderVector3, EscapesStringsInTheValue) {
  const auto box = parse("[box]\nsize = [\"a\\\"b\", 1]\n").table("box");
  EXPECT_EQ(config_error_of([&] { (void)box.optional_vector3("size", Range::any(), "m"); }),
            R"(box.size = ["a\"b", 1]: expected [x, y, z] (m))");
}

TEST(TableReaderVector3List, ReadsEveryVector) {
  const auto field = parse("[field]\nvalues = [[0, 0, 0], [0.1, 0, -0.2]]\n").table("field");
  const auto values = field.optional_vector3_list("values", Range::any(), "T", 1);
  ASSERT_TRUE(values.has_value());
  EXPECT_EQ(*values, (std::vector<Vector>{{0, 0, 0}, {0.1, 0, -0.2}}));
  EXPECT_FALSE(field.optional_vector3_list("absent", Range::any(), "T").has_value());
}

TEST(TableReaderVector3List, ReportsListSizeElementsAndComponents) {
  const auto field = parse(
                         "[field]\nscalar = 0.1\nempty = []\none = [[1, 2, 3]]\n"
                         "short = [[0, 0, 0], [0.1, 0]]\nflat = [1, 2, 3]\n"
                         "word = [[0, 0, 0], [0, \"x\", 0]]\nnegative = [[1, 2, -3]]\n")
                         .table("field");
  const auto read = [&](const char* key, std::size_t min_size) {
    return [&field, key, min_size] {
      (void)field.optional_vector3_list(key, Range::non_negative(), "T", min_size);
    };
  };
  EXPECT_EQ(config_error_of(read("scalar", 1)),
            "field.scalar = 0.1: expected a list of [x, y, z] vectors (T)");
  EXPECT_EQ(config_error_of(read("empty", 1)),
            "field.empty = []: expected at least 1 [x, y, z] vector (T)");
  EXPECT_EQ(config_error_of(read("one", 2)),
            "field.one = [[1, 2, 3]]: expected at least 2 [x, y, z] vectors (T)");
  EXPECT_EQ(config_error_of(read("short", 1)), "field.short[1] = [0.1, 0]: expected [x, y, z] (T)");
  EXPECT_EQ(config_error_of(read("flat", 1)), "field.flat[0] = 1: expected [x, y, z] (T)");
  EXPECT_EQ(config_error_of(read("word", 1)), "field.word[1][1] = \"x\": expected a number (T)");
  EXPECT_EQ(config_error_of(read("negative", 1)), "field.negative[0][2] = -3: must be >= 0 (T)");
  const auto unitless = [&] { (void)field.optional_vector3_list("scalar", Range::any(), ""); };
  EXPECT_EQ(config_error_of(unitless), "field.scalar = 0.1: expected a list of [x, y, z] vectors");
}

TEST(TableReaderInteger3, ReadsThreeIntegers) {
  const auto particles = parse("[particles]\ncount_per_axis = [1, 1, 2]\n").table("particles");
  EXPECT_EQ(particles.optional_integer3("count_per_axis", Range::between(1, 10000)),
            (std::array<long, 3>{1, 1, 2}));
  EXPECT_FALSE(particles.optional_integer3("absent", Range::any()).has_value());
}

TEST(TableReaderInteger3, ReportsShapeTypeAndRange) {
  const auto particles = parse(
                             "[particles]\nscalar = 2\ntwo = [1, 2]\nword = [1, \"1\", 2]\n"
                             "whole = [1, 2.0, 2]\nzero = [1, 0, 2]\n")
                             .table("particles");
  const auto read = [&](const char* key) {
    return [&particles, key] { (void)particles.optional_integer3(key, Range::between(1, 10)); };
  };
  EXPECT_EQ(config_error_of(read("scalar")),
            "particles.scalar = 2: expected three integers [x, y, z]");
  EXPECT_EQ(config_error_of(read("two")),
            "particles.two = [1, 2]: expected three integers [x, y, z]");
  EXPECT_EQ(config_error_of(read("word")), "particles.word[1] = \"1\": expected an integer");
  EXPECT_EQ(config_error_of(read("whole")), "particles.whole[1] = 2.0: expected an integer");
  EXPECT_EQ(config_error_of(read("zero")), "particles.zero[1] = 0: must be in [1, 10]");
}

TEST(TableReaderArrays, GettersMarkKeysKnownIsArrayDoesNot) {
  const auto root = parse("[t]\nv = [1, 2, 3]\nl = [[1, 2, 3]]\nn = [1, 1, 1]\nx = [1]\ns = 2\n");
  const auto t = root.table("t");
  EXPECT_TRUE(t.is_array("v"));
  EXPECT_TRUE(t.is_array("x"));
  EXPECT_FALSE(t.is_array("s"));
  EXPECT_FALSE(t.is_array("absent"));
  (void)t.optional_vector3("v", Range::any(), "");
  (void)t.optional_vector3_list("l", Range::any(), "");
  (void)t.optional_integer3("n", Range::any());
  (void)t.optional_vector3("absent", Range::any(), "");
  (void)t.optional_number("s", Range::any(), "");
  // x was only tested with is_array(): still unknown; absent is listed as allowed.
  EXPECT_EQ(unknown_of(root), "unknown key 't.x' in [t]; allowed keys: absent, l, n, s, v");
}

TEST(TableReaderArrays, VectorTextWritesNumbersAsTheReaderDoes) {
  EXPECT_EQ(vector_text({6e-6, 6e-6, 1.5e-5}), "[6e-06, 6e-06, 1.5e-05]");
  EXPECT_EQ(vector_text({0.0, 1.0, -2.5}), "[0.0, 1.0, -2.5]");
}

enum class Sequence { loop, up };

TEST(TableReaderEnumeration, ReturnsTheValuePairedWithTheName) {
  const auto field = parse("[field]\nsequence = \"up\"\n").table("field");
  EXPECT_EQ(
      field.enumeration<Sequence>("sequence", {{"loop", Sequence::loop}, {"up", Sequence::up}}),
      Sequence::up);
  EXPECT_EQ(field.enumeration_or("sequence", Sequence::loop,
                                 {{"loop", Sequence::loop}, {"up", Sequence::up}}),
            Sequence::up);
  EXPECT_EQ(field.enumeration_or("absent", Sequence::loop,
                                 {{"loop", Sequence::loop}, {"up", Sequence::up}}),
            Sequence::loop);
  // Several names may stand for one value (aliases); ints work as well as enums.
  EXPECT_EQ(field.enumeration_or("sequence", 0, {{"rising", 1}, {"up", 1}, {"loop", 2}}), 1);
}

TEST(TableReaderEnumeration, MessagesAreThoseOfChoice) {
  const auto root = parse("[field]\nsequence = \"lop\"\nnumber = 1\nsequense = \"up\"\n");
  const auto field = root.table("field");
  const auto options = [](const TableReader& t, const char* key) {
    return [&t, key] {
      (void)t.enumeration<Sequence>(key, {{"loop", Sequence::loop}, {"up", Sequence::up}});
    };
  };
  EXPECT_EQ(config_error_of(options(field, "sequence")),
            "field.sequence = \"lop\": must be one of loop, up");
  EXPECT_EQ(config_error_of(options(field, "number")),
            "field.number = 1: expected a string, one of loop, up");
  EXPECT_EQ(config_error_of(options(field, "absent")),
            "missing key 'field.absent' (one of loop, up)");
  const auto other = parse("[field]\nsequense = \"up\"\n").table("field");
  EXPECT_EQ(config_error_of(options(other, "sequence")),
            "missing key 'field.sequence' (one of loop, up); the file has 'field.sequense' - a "
            "misspelling?");
  EXPECT_EQ(config_error_of([&] {
              (void)field.enumeration_or("sequence", Sequence::up,
                                         {{"up", Sequence::up}, {"loop", Sequence::loop}});
            }),
            "field.sequence = \"lop\": must be one of up, loop");
}

TEST(TableReaderEnumeration, AbsentKeyWithFallbackIsKnown) {
  const auto root = parse("[field]\nother = 1\n");
  const auto field = root.table("field");
  EXPECT_EQ(field.enumeration_or("sequence", Sequence::up, {{"loop", Sequence::loop}}),
            Sequence::up);
  EXPECT_EQ(unknown_of(root), "unknown key 'field.other' in [field]; allowed keys: sequence");
}

}  // namespace
}  // namespace mresim::config
