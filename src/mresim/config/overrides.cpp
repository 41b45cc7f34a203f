#include "mresim/config/overrides.hpp"

#include <fmt/format.h>

#include <cstddef>
#include <optional>
#include <sstream>
#include <utility>

#include "mresim/config/config_error.hpp"

namespace mresim::config {

namespace {

constexpr std::string_view kOption = "--set: ";
constexpr std::string_view kForm = "expected KEY=VALUE, e.g. field.max=0.5";

// One step of KEY: a bare key, optionally indexing the array it names ("case[1]").
struct KeyPart {
  std::string name;
  std::optional<std::size_t> index;
};

// One argument, split and checked; `value` holds the new value under the key "v".
struct Override {
  std::string argument;
  std::vector<KeyPart> key;
  toml::table value;
};

[[noreturn]] void fail(std::string_view argument, std::string_view what) {
  throw ConfigError(fmt::format("{}{}: {}", kOption, argument, what));
}

std::string_view trim(std::string_view s) {
  const auto first = s.find_first_not_of(" \t");
  if (first == std::string_view::npos) return {};
  return s.substr(first, s.find_last_not_of(" \t") - first + 1);
}

bool is_bare_key_char(char c) {
  return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_' ||
         c == '-';
}

KeyPart parse_key_part(std::string_view argument, std::string_view key, std::string_view part) {
  KeyPart result;
  std::size_t end = 0;
  while (end < part.size() && is_bare_key_char(part[end])) ++end;
  result.name = std::string(part.substr(0, end));
  const std::string_view rest = part.substr(end);
  const auto bad_part = [&] {
    fail(argument,
         fmt::format("'{}' in KEY '{}' is not a bare TOML key (letters, digits, _ and - only, "
                     "optionally followed by an index such as [1])",
                     part, key));
  };
  if (result.name.empty()) bad_part();
  if (rest.empty()) return result;
  // "[digits]": an index into an existing array.
  if (rest.size() < 3 || rest.front() != '[' || rest.back() != ']') bad_part();
  std::size_t index = 0;
  for (const char c : rest.substr(1, rest.size() - 2)) {
    if (c < '0' || c > '9' || index > 1'000'000) bad_part();
    index = index * 10 + static_cast<std::size_t>(c - '0');
  }
  result.index = index;
  return result;
}

Override parse_override(std::string_view argument) {
  Override result;
  result.argument = std::string(argument);
  const auto equals = argument.find('=');
  if (equals == std::string_view::npos) fail(argument, kForm);
  const std::string_view key = trim(argument.substr(0, equals));
  if (key.empty()) fail(argument, fmt::format("empty KEY before '='; {}", kForm));
  for (std::size_t start = 0;;) {
    const auto dot = key.find('.', start);
    const std::string_view part =
        key.substr(start, dot == std::string_view::npos ? std::string_view::npos : dot - start);
    if (part.empty()) {
      fail(argument, fmt::format("empty part in KEY '{}' (a dotted path such as field.max)", key));
    }
    result.key.push_back(parse_key_part(argument, key, part));
    if (dot == std::string_view::npos) break;
    start = dot + 1;
  }

  const std::string_view value = trim(argument.substr(equals + 1));
  if (value.empty()) fail(argument, "empty VALUE; write \"\" for an empty string");
  const std::string document = fmt::format("v = {}", value);
  try {
    result.value = toml::parse(std::string_view(document), std::string_view("--set"));
  } catch (const toml::parse_error& e) {
    // Not TOML: a bare word is a string (model.profile=seed); what starts like a quoted string,
    // an array or an inline table was meant as TOML and is refused rather than guessed at.
    if (value.find_first_of("\"'[{") == 0) {
      std::string description(e.description());
      for (char& c : description) {
        if (c == '\n' || c == '\r') c = ' ';
      }
      fail(argument, fmt::format("VALUE {} is not a valid TOML value: {}", value, description));
    }
    result.value = toml::table{};
    result.value.insert_or_assign("v", std::string(value));
  }
  if (result.value.size() != 1 || !result.value.contains("v")) {
    fail(argument, fmt::format("VALUE {} is not one TOML value", value));
  }
  return result;
}

std::string type_name(const toml::node& node) {
  if (node.is_table()) return "a table";
  if (node.is_array()) return "an array";
  if (node.is_string()) return "a string";
  if (node.is_integer()) return "an integer";
  if (node.is_floating_point()) return "a float";
  if (node.is_boolean()) return "a boolean";
  return "a date/time";
}

// The value roughly as written, on one line, as TableReader's messages show values.
std::string value_text(const toml::node& node) {
  if (node.is_table()) return "{...}";
  std::string text;
  if (const auto* s = node.as_string()) {
    text.push_back('"');
    for (const char c : s->get()) {
      if (c == '"' || c == '\\') text += '\\';
      text.push_back(c);
    }
    text.push_back('"');
  } else {
    std::ostringstream out;
    node.visit([&](const auto& n) { out << n; });
    text = out.str();
  }
  for (char& c : text) {
    if (c == '\n' || c == '\r') c = ' ';
  }
  constexpr std::size_t kMaxShown = 40;
  if (text.size() > kMaxShown) text = text.substr(0, kMaxShown) + "...";
  return text;
}

// Puts `value` (moved) at `key` of `root`, creating the tables on the way.
void apply(toml::table& root, Override& override) {
  toml::node& value = *override.value.get("v");
  toml::table* table = &root;
  std::string shown;  // the dotted path so far, as messages name it
  for (std::size_t i = 0; i < override.key.size(); ++i) {
    const KeyPart& part = override.key[i];
    const bool last = i + 1 == override.key.size();
    shown = shown.empty() ? part.name : fmt::format("{}.{}", shown, part.name);
    toml::node* node = table->get(part.name);
    if (part.index) {
      const std::string element = fmt::format("{}[{}]", shown, *part.index);
      toml::array* array = node == nullptr ? nullptr : node->as_array();
      if (array == nullptr) {
        fail(override.argument, node == nullptr
                                    ? fmt::format("there is no array {} to index", shown)
                                    : fmt::format("{} = {} is {}, not an array", shown,
                                                  value_text(*node), type_name(*node)));
      }
      if (*part.index >= array->size()) {
        fail(override.argument,
             fmt::format("{} has {} entries, so there is no {}", shown, array->size(), element));
      }
      shown = element;
      const auto position = array->cbegin() + static_cast<std::ptrdiff_t>(*part.index);
      if (last) {
        std::move(value).visit(
            [&](auto&& v) { array->replace(position, std::forward<decltype(v)>(v)); });
        return;
      }
      node = array->get(*part.index);
    } else if (last) {
      std::move(value).visit(
          [&](auto&& v) { table->insert_or_assign(part.name, std::forward<decltype(v)>(v)); });
      return;
    }
    if (node == nullptr) {
      node = &table->insert_or_assign(part.name, toml::table{}).first->second;
    }
    table = node->as_table();
    if (table == nullptr) {
      fail(override.argument,
           fmt::format("{} = {} is {}, not a table", shown, value_text(*node), type_name(*node)));
    }
  }
}

}  // namespace

std::string override_syntax_error(std::string_view argument) {
  try {
    (void)parse_override(argument);
  } catch (const ConfigError& e) {
    return std::string(e.what()).substr(kOption.size());
  }
  return {};
}

void apply_overrides(toml::table& root, const std::vector<std::string>& arguments) {
  for (const std::string& argument : arguments) {
    Override override = parse_override(argument);
    apply(root, override);
  }
}

std::string toml_text(const toml::table& root) {
  std::ostringstream out;
  out << toml::toml_formatter(root);
  std::string text = out.str();
  if (!text.empty() && text.back() != '\n') text += '\n';
  return text;
}

}  // namespace mresim::config
