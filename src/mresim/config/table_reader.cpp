#include "mresim/config/table_reader.hpp"

#include <fmt/format.h>
#include <toml++/toml.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <set>
#include <stdexcept>
#include <tuple>

#include "mresim/config/overrides.hpp"

namespace mresim::config {

namespace detail {
// One parsed run file plus the keys the program has asked for, per table path. Shared by every
// TableReader made from it so that reject_unknown_keys() sees all reads.
struct Document {
  std::string source_name;
  std::string text;       // what root was parsed from: the effective run file
  std::string file_text;  // the file as written (differs from text only with overrides)
  std::vector<std::string> overrides;
  toml::table root;
  std::map<std::string, std::set<std::string>, std::less<>> known;
};
}  // namespace detail

namespace {

const toml::table& as_table(const void* p) { return *static_cast<const toml::table*>(p); }
const toml::node* as_node(const void* p) { return static_cast<const toml::node*>(p); }

std::string unit_suffix(std::string_view unit) {
  return unit.empty() ? std::string{} : fmt::format(" ({})", unit);
}

std::string join_path(std::string_view parent, std::string_view key) {
  return parent.empty() ? std::string(key) : fmt::format("{}.{}", parent, key);
}

std::string join(const std::vector<std::string>& items) {
  return fmt::format("{}", fmt::join(items, ", "));
}

// Shortest text that reads back to the same double, keeping a float recognisable as one
// ("2.0", not "2", so that "expected an integer" makes sense).
std::string format_float(double x) {
  std::string text = fmt::format("{}", x);
  if (text.find_first_of(".eEni") == std::string::npos) text += ".0";
  return text;
}

// The value roughly as the user wrote it, short enough for a one-line message.
std::string format_node(const toml::node& node) {
  if (const auto* s = node.as_string()) return toml_string_literal(s->get());
  if (const auto* i = node.as_integer()) return fmt::format("{}", i->get());
  if (const auto* f = node.as_floating_point()) return format_float(f->get());
  if (const auto* b = node.as_boolean()) return b->get() ? "true" : "false";
  if (const auto* a = node.as_array()) {
    constexpr std::size_t kMaxShown = 6;
    std::vector<std::string> items;
    for (std::size_t i = 0; i < a->size() && i < kMaxShown; ++i)
      items.push_back(format_node(*a->get(i)));
    if (a->size() > kMaxShown) items.emplace_back("...");
    return fmt::format("[{}]", join(items));
  }
  if (node.is_table()) return "{...}";
  return "(date/time)";
}

// Optimal-string-alignment distance (edits incl. swapping two neighbours), case-insensitive.
std::size_t edit_distance(std::string_view a, std::string_view b) {
  const auto lower = [](char c) {
    return static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  };
  std::vector<std::vector<std::size_t>> d(a.size() + 1, std::vector<std::size_t>(b.size() + 1));
  for (std::size_t i = 0; i <= a.size(); ++i) d[i][0] = i;
  for (std::size_t j = 0; j <= b.size(); ++j) d[0][j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t cost = lower(a[i - 1]) == lower(b[j - 1]) ? 0 : 1;
      d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + cost});
      if (i > 1 && j > 1 && lower(a[i - 1]) == lower(b[j - 2]) &&
          lower(a[i - 2]) == lower(b[j - 1])) {
        d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
      }
    }
  }
  return d[a.size()][b.size()];
}

// How many edits still count as a typo: short names differ from each other by one letter too
// often ("k" vs "R") to guess.
std::size_t typo_tolerance(std::size_t length) {
  if (length <= 2) return 0;
  if (length <= 4) return 1;
  return 2;
}

bool is_table_like(const toml::node& node) {
  if (node.is_table()) return true;
  const auto* a = node.as_array();
  return a != nullptr && !a->empty() && a->is_array_of_tables();
}

// The parser's description may quote the offending input, line breaks included; an error is one
// line (found by the run-file fuzzer: `demagnetization = fal` at the end of a line).
std::string one_line(std::string_view text) {
  std::string out;
  for (const char c : text) {
    if (c == '\n') {
      out += "\\n";
    } else if (c == '\r') {
      out += "\\r";
    } else if (static_cast<unsigned char>(c) < 0x20) {
      out += ' ';
    } else {
      out += c;
    }
  }
  return out;
}

[[noreturn]] void fail_at(const std::string& key_path, const toml::node& node,
                          std::string_view what_is_allowed) {
  throw ConfigError(fmt::format("{} = {}: {}", key_path, format_node(node), what_is_allowed));
}

// A finite TOML integer or float inside `range`; `key_path` names it ("field.values[1][0]").
double number_at(const toml::node& node, const std::string& key_path, Range range,
                 std::string_view unit) {
  double value = 0.0;
  if (const auto* i = node.as_integer()) {
    value = static_cast<double>(i->get());
  } else if (const auto* f = node.as_floating_point()) {
    value = f->get();
  } else {
    fail_at(key_path, node, fmt::format("expected a number{}", unit_suffix(unit)));
  }
  if (!std::isfinite(value)) {
    fail_at(key_path, node, fmt::format("expected a finite number{}", unit_suffix(unit)));
  }
  if (!range.contains(value)) {
    fail_at(key_path, node, fmt::format("{}{}", range.describe(), unit_suffix(unit)));
  }
  return value;
}

std::array<double, 3> vector3_at(const toml::node& node, const std::string& key_path, Range range,
                                 std::string_view unit) {
  const auto* array = node.as_array();
  if (array == nullptr || array->size() != 3) {
    fail_at(key_path, node, fmt::format("expected [x, y, z]{}", unit_suffix(unit)));
  }
  std::array<double, 3> v{};
  for (std::size_t a = 0; a < 3; ++a) {
    v.at(a) = number_at(*array->get(a), fmt::format("{}[{}]", key_path, a), range, unit);
  }
  return v;
}

}  // namespace

TableReader::TableReader(std::shared_ptr<detail::Document> doc, const void* table, std::string path)
    : doc_(std::move(doc)), table_(table), path_(std::move(path)) {}

TableReader TableReader::parse_file(const std::filesystem::path& file) {
  return parse_file(file, {});
}

TableReader TableReader::parse_file(const std::filesystem::path& file,
                                    const std::vector<std::string>& overrides) {
  const std::string name = file.string();
  std::error_code ec;
  if (std::filesystem::is_directory(file, ec)) {
    throw ConfigError(fmt::format("cannot read run file '{}': it is a directory", name));
  }
  std::FILE* f = std::fopen(file.c_str(), "rb");
  if (f == nullptr) {
    throw ConfigError(fmt::format("cannot read run file '{}': {}", name, std::strerror(errno)));
  }
  std::string text;
  char buffer[1 << 14];
  std::size_t n = 0;
  while ((n = std::fread(buffer, 1, sizeof buffer, f)) > 0) text.append(buffer, n);
  const bool failed = std::ferror(f) != 0;
  const int read_errno = errno;
  std::fclose(f);
  if (failed) {
    throw ConfigError(
        fmt::format("cannot read run file '{}': {}", name, std::strerror(read_errno)));
  }
  return parse_string(text, name, overrides);
}

TableReader TableReader::parse_string(std::string_view text, std::string source_name) {
  return parse_string(text, std::move(source_name), {});
}

TableReader TableReader::parse_string(std::string_view text, std::string source_name,
                                      const std::vector<std::string>& overrides) {
  auto doc = std::make_shared<detail::Document>();
  doc->source_name = std::move(source_name);
  doc->text = std::string(text);
  const auto parse = [&doc] {
    try {
      doc->root = toml::parse(std::string_view(doc->text), std::string_view(doc->source_name));
    } catch (const toml::parse_error& e) {
      throw ConfigError(fmt::format("{}:{}:{}: TOML syntax error: {}", doc->source_name,
                                    e.source().begin.line, e.source().begin.column,
                                    one_line(e.description())));
    }
  };
  parse();
  if (!overrides.empty()) {
    apply_overrides(doc->root, overrides);
    doc->file_text = std::move(doc->text);
    doc->overrides = overrides;
    doc->text = toml_text(doc->root);
    // Read the effective text back, so that the readers see exactly what is recorded.
    parse();
  } else {
    doc->file_text = doc->text;
  }
  const void* root = &doc->root;
  return {std::move(doc), root, ""};
}

std::string TableReader::path(std::string_view key) const { return join_path(path_, key); }

const std::string& TableReader::source_text() const { return doc_->text; }
const std::string& TableReader::source_name() const { return doc_->source_name; }
const std::string& TableReader::file_text() const { return doc_->file_text; }
const std::vector<std::string>& TableReader::overrides() const { return doc_->overrides; }

const void* TableReader::lookup(std::string_view key) const {
  auto it = doc_->known.find(path_);
  if (it == doc_->known.end()) it = doc_->known.emplace(path_, std::set<std::string>{}).first;
  it->second.emplace(key);
  return as_table(table_).get(key);
}

bool TableReader::has(std::string_view key) const { return as_table(table_).contains(key); }

std::string TableReader::value_text(std::string_view key) const {
  const toml::node* node = as_table(table_).get(key);
  return node == nullptr ? std::string{} : format_node(*node);
}

void TableReader::fail(std::string_view key, std::string_view value_text,
                       std::string_view what_is_allowed) const {
  throw ConfigError(fmt::format("{} = {}: {}", path(key), value_text, what_is_allowed));
}

void TableReader::fail(std::string_view key, double value, std::string_view what_is_allowed) const {
  fail(key, fmt::format("{}", value), what_is_allowed);
}

std::string TableReader::misspelling_hint(std::string_view key) const {
  return misspelling_hint_for(key, false);
}

// A missing key is very often a misspelt one: point at the closest key nobody asked for.
std::string TableReader::misspelling_hint_for(std::string_view key, bool table) const {
  const auto known = doc_->known.find(path_);
  std::string best;
  std::size_t best_distance = typo_tolerance(key.size()) + 1;
  for (const auto& [k, node] : as_table(table_)) {
    const std::string_view name = k.str();
    if (known != doc_->known.end() && known->second.contains(std::string(name))) continue;
    const std::size_t dist = edit_distance(key, name);
    if (dist < best_distance) {
      best_distance = dist;
      best = std::string(name);
    }
  }
  if (best.empty()) return {};
  return table ? fmt::format("; the file has [{}] - a misspelling?", path(best))
               : fmt::format("; the file has '{}' - a misspelling?", path(best));
}

void TableReader::fail_missing(std::string_view key, std::string_view kind,
                               std::string_view detail) const {
  std::string message = kind == "table" ? fmt::format("missing table [{}]", path(key))
                                        : fmt::format("missing key '{}'", path(key));
  message += detail;
  message += kind == "table" ? misspelling_hint_for(key, true) : misspelling_hint(key);
  throw ConfigError(message);
}

double TableReader::number(std::string_view key, Range range, std::string_view unit) const {
  const void* node = lookup(key);
  if (node == nullptr) fail_missing(key, "key", unit_suffix(unit));
  return number_at(*as_node(node), path(key), range, unit);
}

double TableReader::number_or(std::string_view key, double fallback, Range range,
                              std::string_view unit) const {
  return optional_number(key, range, unit).value_or(fallback);
}

std::optional<double> TableReader::optional_number(std::string_view key, Range range,
                                                   std::string_view unit) const {
  const void* node = lookup(key);
  if (node == nullptr) return std::nullopt;
  return number_at(*as_node(node), path(key), range, unit);
}

long TableReader::integer(std::string_view key, Range range) const {
  const void* node_ptr = lookup(key);
  if (node_ptr == nullptr) fail_missing(key, "key", "");
  const toml::node& node = *as_node(node_ptr);
  const auto* i = node.as_integer();
  if (i == nullptr) fail(key, format_node(node), "expected an integer");
  const long value = static_cast<long>(i->get());
  if (!range.contains(static_cast<double>(value))) fail(key, format_node(node), range.describe());
  return value;
}

long TableReader::integer_or(std::string_view key, long fallback, Range range) const {
  if (!has(key)) {
    (void)lookup(key);
    return fallback;
  }
  return integer(key, range);
}

bool TableReader::boolean_or(std::string_view key, bool fallback) const {
  const void* node_ptr = lookup(key);
  if (node_ptr == nullptr) return fallback;
  const toml::node& node = *as_node(node_ptr);
  const auto* b = node.as_boolean();
  if (b == nullptr) fail(key, format_node(node), "expected true or false");
  return b->get();
}

std::string TableReader::string_or(std::string_view key, std::string fallback) const {
  const void* node_ptr = lookup(key);
  if (node_ptr == nullptr) return fallback;
  const toml::node& node = *as_node(node_ptr);
  const auto* s = node.as_string();
  if (s == nullptr) fail(key, format_node(node), "expected a string");
  return s->get();
}

std::string TableReader::choice(std::string_view key,
                                const std::vector<std::string>& allowed) const {
  const std::string options = join(allowed);
  const void* node_ptr = lookup(key);
  if (node_ptr == nullptr) fail_missing(key, "key", fmt::format(" (one of {})", options));
  const toml::node& node = *as_node(node_ptr);
  const auto* s = node.as_string();
  if (s == nullptr)
    fail(key, format_node(node), fmt::format("expected a string, one of {}", options));
  if (std::find(allowed.begin(), allowed.end(), s->get()) == allowed.end()) {
    fail(key, format_node(node), fmt::format("must be one of {}", options));
  }
  return s->get();
}

std::string TableReader::choice_or(std::string_view key, std::string fallback,
                                   const std::vector<std::string>& allowed) const {
  if (!has(key)) {
    (void)lookup(key);
    return fallback;
  }
  return choice(key, allowed);
}

std::vector<double> TableReader::number_list(std::string_view key, Range range,
                                             std::string_view unit, std::size_t min_size) const {
  auto list = optional_number_list(key, range, unit, min_size);
  if (!list) fail_missing(key, "key", unit_suffix(unit));
  return *list;
}

std::optional<std::vector<double>> TableReader::optional_number_list(std::string_view key,
                                                                     Range range,
                                                                     std::string_view unit,
                                                                     std::size_t min_size) const {
  const void* node_ptr = lookup(key);
  if (node_ptr == nullptr) return std::nullopt;
  const toml::node& node = *as_node(node_ptr);
  const auto* array = node.as_array();
  if (array == nullptr) {
    fail(key, format_node(node), fmt::format("expected a list of numbers{}", unit_suffix(unit)));
  }
  if (array->size() < min_size) {
    fail(key, format_node(node),
         fmt::format("expected at least {} value{}{}", min_size, min_size == 1 ? "" : "s",
                     unit_suffix(unit)));
  }
  std::vector<double> values;
  values.reserve(array->size());
  for (std::size_t i = 0; i < array->size(); ++i) {
    values.push_back(number_at(*array->get(i), fmt::format("{}[{}]", path(key), i), range, unit));
  }
  return values;
}

std::optional<std::array<double, 3>> TableReader::optional_vector3(std::string_view key,
                                                                   Range range,
                                                                   std::string_view unit) const {
  const void* node_ptr = lookup(key);
  if (node_ptr == nullptr) return std::nullopt;
  return vector3_at(*as_node(node_ptr), path(key), range, unit);
}

std::optional<std::vector<std::array<double, 3>>> TableReader::optional_vector3_list(
    std::string_view key, Range range, std::string_view unit, std::size_t min_size) const {
  const void* node_ptr = lookup(key);
  if (node_ptr == nullptr) return std::nullopt;
  const toml::node& node = *as_node(node_ptr);
  const std::string key_path = path(key);
  const auto* array = node.as_array();
  if (array == nullptr) {
    fail_at(key_path, node,
            fmt::format("expected a list of [x, y, z] vectors{}", unit_suffix(unit)));
  }
  if (array->size() < min_size) {
    fail_at(key_path, node,
            fmt::format("expected at least {} [x, y, z] vector{}{}", min_size,
                        min_size == 1 ? "" : "s", unit_suffix(unit)));
  }
  std::vector<std::array<double, 3>> vectors;
  vectors.reserve(array->size());
  for (std::size_t i = 0; i < array->size(); ++i) {
    vectors.push_back(vector3_at(*array->get(i), fmt::format("{}[{}]", key_path, i), range, unit));
  }
  return vectors;
}

std::optional<std::array<long, 3>> TableReader::optional_integer3(std::string_view key,
                                                                  Range range) const {
  const void* node_ptr = lookup(key);
  if (node_ptr == nullptr) return std::nullopt;
  const toml::node& node = *as_node(node_ptr);
  const std::string key_path = path(key);
  const auto* array = node.as_array();
  if (array == nullptr || array->size() != 3) {
    fail_at(key_path, node, "expected three integers [x, y, z]");
  }
  std::array<long, 3> values{};
  for (std::size_t a = 0; a < 3; ++a) {
    const toml::node& item = *array->get(a);
    const std::string item_path = fmt::format("{}[{}]", key_path, a);
    const auto* i = item.as_integer();
    if (i == nullptr) fail_at(item_path, item, "expected an integer");
    const auto value = static_cast<long>(i->get());
    if (!range.contains(static_cast<double>(value))) fail_at(item_path, item, range.describe());
    values.at(a) = value;
  }
  return values;
}

bool TableReader::is_array(std::string_view key) const {
  const toml::node* node = as_table(table_).get(key);
  return node != nullptr && node->is_array();
}

std::optional<std::size_t> TableReader::choice_index(std::string_view key,
                                                     const std::vector<std::string>& names,
                                                     bool required) const {
  if (!required && !has(key)) {
    (void)lookup(key);
    return std::nullopt;
  }
  const std::string name = choice(key, names);
  return static_cast<std::size_t>(std::find(names.begin(), names.end(), name) - names.begin());
}

std::string vector_text(const std::array<double, 3>& v) {
  return fmt::format("[{}, {}, {}]", format_float(v[0]), format_float(v[1]), format_float(v[2]));
}

TableReader TableReader::table(std::string_view key) const {
  auto sub = optional_table(key);
  if (!sub) fail_missing(key, "table", "");
  return *sub;
}

std::optional<TableReader> TableReader::optional_table(std::string_view key) const {
  const void* node_ptr = lookup(key);
  if (node_ptr == nullptr) return std::nullopt;
  const toml::node& node = *as_node(node_ptr);
  const auto* sub = node.as_table();
  if (sub == nullptr) fail(key, format_node(node), fmt::format("expected a table [{}]", path(key)));
  return TableReader(doc_, sub, path(key));
}

std::vector<TableReader> TableReader::table_list(std::string_view key) const {
  const void* node_ptr = lookup(key);
  if (node_ptr == nullptr) return {};
  const toml::node& node = *as_node(node_ptr);
  const auto* array = node.as_array();
  if (array == nullptr || (!array->empty() && !array->is_array_of_tables())) {
    fail(key, format_node(node), fmt::format("expected an array of tables [[{}]]", path(key)));
  }
  std::vector<TableReader> tables;
  for (std::size_t i = 0; i < array->size(); ++i) {
    tables.push_back(
        TableReader(doc_, array->get(i)->as_table(), fmt::format("{}[{}]", path(key), i)));
  }
  return tables;
}

void TableReader::reject_unknown_keys() const {
  struct Unknown {
    std::uint32_t line;
    std::uint32_t column;
    std::string message;
  };
  std::vector<Unknown> unknown;

  const auto allowed_in = [this](const std::string& table_path) {
    const auto it = doc_->known.find(table_path);
    if (it == doc_->known.end() || it->second.empty()) return std::string("(none)");
    return join(std::vector<std::string>(it->second.begin(), it->second.end()));
  };

  const auto walk = [&](const auto& self, const toml::table& table,
                        const std::string& table_path) -> void {
    const auto known = doc_->known.find(table_path);
    for (const auto& [k, node] : table) {
      const std::string name(k.str());
      const std::string full = join_path(table_path, name);
      const bool is_known = known != doc_->known.end() && known->second.contains(name);
      if (!is_known) {
        std::string message;
        if (is_table_like(node)) {
          message = table_path.empty() ? fmt::format("unknown table [{}]; allowed: {}", full,
                                                     allowed_in(table_path))
                                       : fmt::format("unknown table [{}]; allowed in [{}]: {}",
                                                     full, table_path, allowed_in(table_path));
        } else {
          message = table_path.empty() ? fmt::format("unknown key '{}' at top level; allowed: {}",
                                                     full, allowed_in(table_path))
                                       : fmt::format("unknown key '{}' in [{}]; allowed keys: {}",
                                                     full, table_path, allowed_in(table_path));
        }
        unknown.push_back({k.source().begin.line, k.source().begin.column, std::move(message)});
        continue;
      }
      if (const auto* sub = node.as_table()) {
        self(self, *sub, full);
      } else if (const auto* array = node.as_array();
                 array != nullptr && array->is_array_of_tables()) {
        for (std::size_t i = 0; i < array->size(); ++i) {
          self(self, *array->get(i)->as_table(), fmt::format("{}[{}]", full, i));
        }
      }
    }
  };
  walk(walk, as_table(table_), path_);

  if (unknown.empty()) return;
  const auto first =
      std::min_element(unknown.begin(), unknown.end(), [](const auto& a, const auto& b) {
        return std::tie(a.line, a.column) < std::tie(b.line, b.column);
      });
  throw ConfigError(first->message);
}

std::string toml_string_literal(std::string_view text) {
  std::string out = "\"";
  for (const char c : text) {
    switch (c) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\t':
        out += "\\t";
        break;
      case '\r':
        out += "\\r";
        break;
      default:
        out += c;
    }
  }
  return out + "\"";
}

}  // namespace mresim::config
