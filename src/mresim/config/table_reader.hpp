#pragma once

#include <cstddef>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "mresim/config/config_error.hpp"
#include "mresim/config/range.hpp"

namespace mresim::config {

namespace detail {
struct Document;
}

// Read access to one table of a parsed TOML run file, with validation.
//
// Every getter names the full dotted key in its error ("model.k = -0.04: must be > 0 (N/m)") and
// throws ConfigError. Every key a getter asks for, present or not, is recorded as "known" in
// state shared by all readers of the same document; after a run type has read everything it
// understands, reject_unknown_keys() on the root reports the first key nobody asked for (a typo
// must never be silently ignored). Consequence for callers: read every key up front (in the
// plan factory), not lazily during execution. has() alone does not mark a key as known.
//
// Readers are cheap to copy (a shared pointer and a path). Not thread-safe: read the
// configuration on one thread before starting parallel work.
class TableReader {
 public:
  // Missing/unreadable file: "cannot read run file 'X': <reason>".
  // Syntax error: "X:LINE:COL: TOML syntax error: <what>".
  static TableReader parse_file(const std::filesystem::path& file);
  // source_name stands in for the file name in messages ("<string>", "test.toml").
  static TableReader parse_string(std::string_view text, std::string source_name);

  // A finite number (TOML integer or float) inside `range`. `unit` (e.g. "N/m", "T", "" for
  // none) is shown in messages. Missing: "missing key 'model.k' (N/m)".
  [[nodiscard]] double number(std::string_view key, Range range, std::string_view unit) const;
  [[nodiscard]] double number_or(std::string_view key, double fallback, Range range,
                                 std::string_view unit) const;
  [[nodiscard]] std::optional<double> optional_number(std::string_view key, Range range,
                                                      std::string_view unit) const;

  // A TOML integer (floats such as 2.5 or 2.0 are rejected) inside `range`.
  [[nodiscard]] long integer(std::string_view key, Range range) const;
  [[nodiscard]] long integer_or(std::string_view key, long fallback, Range range) const;

  [[nodiscard]] bool boolean_or(std::string_view key, bool fallback) const;
  [[nodiscard]] std::string string_or(std::string_view key, std::string fallback) const;

  // A string that must be one of `allowed`: 'penalty.type = "tahn": must be one of tanh, wca'.
  [[nodiscard]] std::string choice(std::string_view key,
                                   const std::vector<std::string>& allowed) const;
  [[nodiscard]] std::string choice_or(std::string_view key, std::string fallback,
                                      const std::vector<std::string>& allowed) const;

  // An array of finite numbers, each inside `range`, with at least `min_size` entries.
  [[nodiscard]] std::vector<double> number_list(std::string_view key, Range range,
                                                std::string_view unit,
                                                std::size_t min_size = 1) const;
  [[nodiscard]] std::optional<std::vector<double>> optional_number_list(
      std::string_view key, Range range, std::string_view unit, std::size_t min_size = 1) const;

  // Whether the key is present (any type). Does not mark the key as known.
  [[nodiscard]] bool has(std::string_view key) const;

  // A required sub-table: "missing table [field]".
  [[nodiscard]] TableReader table(std::string_view key) const;
  [[nodiscard]] std::optional<TableReader> optional_table(std::string_view key) const;
  // An array of tables ([[sweep]] ...); empty when the key is absent. Element i has the path
  // "sweep[i]", so its keys appear as "sweep[1].value" in messages.
  [[nodiscard]] std::vector<TableReader> table_list(std::string_view key) const;

  // The dotted path of `key` in this table ("model.k"), and of this table ("" for the root).
  [[nodiscard]] std::string path(std::string_view key) const;
  [[nodiscard]] const std::string& path() const { return path_; }

  // The value of `key` as written in the file, for callers' own messages ("2e-06", "\"x\"").
  // Empty if the key is absent.
  [[nodiscard]] std::string value_text(std::string_view key) const;

  // Raises a ConfigError in the common format, for checks that involve several keys:
  // fail("S0", 2e-6, "must be > 2R = 3e-06 m") -> "model.S0 = 2e-06: must be > 2R = 3e-06 m".
  [[noreturn]] void fail(std::string_view key, std::string_view value_text,
                         std::string_view what_is_allowed) const;
  [[noreturn]] void fail(std::string_view key, double value,
                         std::string_view what_is_allowed) const;

  // For callers' own "missing key" messages: "; the file has 'field.stpes' - a misspelling?"
  // when this table has a key nobody asked for within a few edits of `key`, else "".
  [[nodiscard]] std::string misspelling_hint(std::string_view key) const;

  // Throws for the first key (in document order) below this table that no getter asked for:
  // "unknown key 'field.stpe' in [field]; allowed keys: angle, max, step" or
  // "unknown table [fiedl]; allowed: field, model, run".
  void reject_unknown_keys() const;

  // The complete text of the run file and the name it was read under.
  [[nodiscard]] const std::string& source_text() const;
  [[nodiscard]] const std::string& source_name() const;

 private:
  TableReader(std::shared_ptr<detail::Document> doc, const void* table, std::string path);

  // Looks `key` up and records it as known. Returns a `const toml::node*` or nullptr.
  [[nodiscard]] const void* lookup(std::string_view key) const;
  [[noreturn]] void fail_missing(std::string_view key, std::string_view kind,
                                 std::string_view detail) const;
  [[nodiscard]] std::string misspelling_hint_for(std::string_view key, bool table) const;
  [[nodiscard]] double to_number(const void* node, const std::string& path, Range range,
                                 std::string_view unit) const;

  std::shared_ptr<detail::Document> doc_;
  // The toml::table this reader looks at. Kept opaque so that this header (included by every
  // run type) does not pull in the whole toml++ parser.
  const void* table_;
  std::string path_;
};

}  // namespace mresim::config
