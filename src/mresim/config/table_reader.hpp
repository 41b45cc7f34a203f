#pragma once

#include <array>
#include <cstddef>
#include <filesystem>
#include <initializer_list>
#include <iterator>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
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

  // The same with command-line overrides ("KEY=VALUE", `mresim run --set`, overrides.hpp)
  // applied to the parsed table before anything reads it. With overrides, source_text() is the
  // effective run file (the overridden table as toml++ writes it) and the readers read that text
  // parsed again, so what is recorded is exactly what was validated and run; file_text() keeps
  // the file as written. Without overrides this is parse_file/parse_string above.
  static TableReader parse_file(const std::filesystem::path& file,
                                const std::vector<std::string>& overrides);
  static TableReader parse_string(std::string_view text, std::string source_name,
                                  const std::vector<std::string>& overrides);

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

  // [x, y, z]: exactly three finite numbers, each inside `range`:
  // "box.size = [1, 2]: expected [x, y, z] (m)", "box.size[1] = -2: must be > 0 (m)".
  // Absent: nullopt (callers say what a missing vector means in their own message).
  [[nodiscard]] std::optional<std::array<double, 3>> optional_vector3(std::string_view key,
                                                                      Range range,
                                                                      std::string_view unit) const;
  // [[x, y, z], ...] with at least `min_size` vectors, every component inside `range`:
  // "field.values[1] = [0.1, 0]: expected [x, y, z] (T)", "field.values[0][2] = ...".
  [[nodiscard]] std::optional<std::vector<std::array<double, 3>>> optional_vector3_list(
      std::string_view key, Range range, std::string_view unit, std::size_t min_size = 1) const;
  // [a, b, c]: exactly three TOML integers (2.0 is rejected), each inside `range`:
  // "particles.count_per_axis[1] = \"1\": expected an integer".
  [[nodiscard]] std::optional<std::array<long, 3>> optional_integer3(std::string_view key,
                                                                     Range range) const;
  // Whether `key` holds an array of any kind (false if absent), for keys that accept a scalar or
  // a vector. Like has(), does not mark the key as known.
  [[nodiscard]] bool is_array(std::string_view key) const;

  // A string naming one of a fixed set of values, returned as the value paired with the name:
  //   t.enumeration_or("sequence", Sequence::up, {{"loop", Sequence::loop}, {"up", Sequence::up}})
  // Messages are choice()'s, naming the options in the order given:
  // 'field.sequence = "lop": must be one of loop, up'.
  template <class E>
  using Options = std::initializer_list<std::pair<std::string_view, E>>;
  template <class E>
  [[nodiscard]] E enumeration(std::string_view key,
                              Options<std::type_identity_t<E>> options) const {
    return value_at(options, choice_index(key, names_of(options), true));
  }
  template <class E>
  [[nodiscard]] E enumeration_or(std::string_view key, E fallback,
                                 Options<std::type_identity_t<E>> options) const {
    const auto index = choice_index(key, names_of(options), false);
    return index ? value_at(options, index) : fallback;
  }

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

  // The complete text of the run file and the name it was read under. With overrides, the
  // effective run file (see parse_string); file_text() is then the file as written.
  [[nodiscard]] const std::string& source_text() const;
  [[nodiscard]] const std::string& source_name() const;
  [[nodiscard]] const std::string& file_text() const;
  // The "KEY=VALUE" overrides applied, in order; empty for a plain file.
  [[nodiscard]] const std::vector<std::string>& overrides() const;

 private:
  TableReader(std::shared_ptr<detail::Document> doc, const void* table, std::string path);

  // Looks `key` up and records it as known. Returns a `const toml::node*` or nullptr.
  [[nodiscard]] const void* lookup(std::string_view key) const;
  [[noreturn]] void fail_missing(std::string_view key, std::string_view kind,
                                 std::string_view detail) const;
  [[nodiscard]] std::string misspelling_hint_for(std::string_view key, bool table) const;
  // The position of the value of `key` in `names` (messages as choice()); nullopt when the key
  // is absent and not `required`.
  [[nodiscard]] std::optional<std::size_t> choice_index(std::string_view key,
                                                        const std::vector<std::string>& names,
                                                        bool required) const;

  template <class E>
  static std::vector<std::string> names_of(Options<E> options) {
    std::vector<std::string> names;
    names.reserve(options.size());
    for (const auto& option : options) names.emplace_back(option.first);
    return names;
  }
  template <class E>
  static E value_at(Options<E> options, std::optional<std::size_t> index) {
    if (!index || *index >= options.size()) {
      throw std::logic_error("TableReader::enumeration: no option at this index");
    }
    return std::next(options.begin(), static_cast<std::ptrdiff_t>(*index))->second;
  }

  std::shared_ptr<detail::Document> doc_;
  // The toml::table this reader looks at. Kept opaque so that this header (included by every
  // run type) does not pull in the whole toml++ parser.
  const void* table_;
  std::string path_;
};

// "[6e-06, 6e-06, 1.5e-05]": the numbers of a vector as the reader writes numbers in its
// messages (shortest round-trip text, floats kept recognisable as floats: "[0.0, 1.0, 2.5]").
[[nodiscard]] std::string vector_text(const std::array<double, 3>& v);

}  // namespace mresim::config
