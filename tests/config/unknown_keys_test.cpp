#include <gtest/gtest.h>

#include <string>

#include "mresim/config/table_reader.hpp"

namespace mresim::config {
namespace {

// Reads what a typical run type would read from `text`, then checks for unknown keys.
std::string unknown_key_error(const std::string& text) {
  const auto root = TableReader::parse_string(text, "test.toml");
  (void)root.table("run").string_or("type", "");
  const auto field = root.table("field");
  (void)field.number("max", Range::positive(), "T");
  (void)field.number_or("step", 0.01, Range::positive(), "T");
  (void)field.number_or("angle", 0.0, Range::between(0, 90), "deg");
  (void)root.optional_table("model");
  try {
    root.reject_unknown_keys();
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "no error";
}

TEST(UnknownKeys, AcceptsADocumentWhoseKeysWereAllRead) {
  EXPECT_EQ(unknown_key_error("[run]\ntype = \"a\"\n[field]\nmax = 1\nstep = 0.1\n"), "no error");
}

TEST(UnknownKeys, NamesTheMisspeltKeyAndTheKeysItsTableTakes) {
  EXPECT_EQ(unknown_key_error("[run]\ntype = \"a\"\n[field]\nmax = 1\nstpe = 0.1\n"),
            "unknown key 'field.stpe' in [field]; allowed keys: angle, max, step");
}

TEST(UnknownKeys, NamesAnUnknownTopLevelTable) {
  EXPECT_EQ(unknown_key_error("[run]\ntype = \"a\"\n[field]\nmax = 1\n[fiedl]\nstep = 1\n"),
            "unknown table [fiedl]; allowed: field, model, run");
}

TEST(UnknownKeys, NamesAnUnknownTopLevelKey) {
  EXPECT_EQ(unknown_key_error("threads = 2\n[run]\ntype = \"a\"\n[field]\nmax = 1\n"),
            "unknown key 'threads' at top level; allowed: field, model, run");
}

TEST(UnknownKeys, ReportsTheFirstUnknownKeyInDocumentOrder) {
  EXPECT_EQ(unknown_key_error("[run]\ntype = \"a\"\nzeta = 1\nalpha = 2\n[field]\nmax = 1\n"),
            "unknown key 'run.zeta' in [run]; allowed keys: type");
}

TEST(UnknownKeys, WalksNestedAndInlineTables) {
  EXPECT_EQ(unknown_key_error("[run]\ntype = \"a\"\n[field]\nmax = 1\n[field.extra]\nx = 1\n"),
            "unknown table [field.extra]; allowed in [field]: angle, max, step");
  EXPECT_EQ(unknown_key_error("run = { type = \"a\", typo = 1 }\n[field]\nmax = 1\n"),
            "unknown key 'run.typo' in [run]; allowed keys: type");
}

TEST(UnknownKeys, AnOpenedButUnreadTableTakesNoKeys) {
  EXPECT_EQ(unknown_key_error("[run]\ntype = \"a\"\n[field]\nmax = 1\n[model]\nk = 1\n"),
            "unknown key 'model.k' in [model]; allowed keys: (none)");
}

TEST(UnknownKeys, HasAloneDoesNotMakeAKeyKnown) {
  const auto root = TableReader::parse_string("x = 1\n", "t.toml");
  EXPECT_TRUE(root.has("x"));
  EXPECT_THROW(root.reject_unknown_keys(), ConfigError);
}

TEST(UnknownKeys, ChecksEveryElementOfAnArrayOfTables) {
  const auto root =
      TableReader::parse_string("[[sweep]]\nk = 1\n[[sweep]]\nk = 2\nkk = 3\n", "t.toml");
  for (const auto& sweep : root.table_list("sweep")) (void)sweep.number("k", Range::any(), "");
  try {
    root.reject_unknown_keys();
    FAIL() << "expected a ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_STREQ(e.what(), "unknown key 'sweep[1].kk' in [sweep[1]]; allowed keys: k");
  }
}

}  // namespace
}  // namespace mresim::config
