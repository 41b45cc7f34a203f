#include "mresim/sweep/sweep_spec.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <sstream>
#include <tuple>
#include <utility>

#include "mresim/config/config_error.hpp"
#include "mresim/config/overrides.hpp"

namespace mresim::sweep {

namespace {

using config::ConfigError;

// One swept key with its list, and where the list was written (to keep the file's order).
struct Axis {
  std::string key;
  const toml::array* values = nullptr;
  std::tuple<std::uint32_t, std::uint32_t> position;
};

bool is_bare_key(std::string_view key) {
  return !key.empty() && std::all_of(key.begin(), key.end(), [](char c) {
    return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_' ||
           c == '-';
  });
}

std::string float_text(double v) {
  if (std::isnan(v)) return "nan";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  std::string text = fmt::format("{}", v);  // shortest text that reads back as v
  if (text.find_first_of(".eE") == std::string::npos) text += ".0";
  return text;
}

// Collects the lists below `table` (a `product` or `zip` table), joining nested table keys with
// dots: `[sweep.product]` with `field.max = [...]` (a dotted key, i.e. nested tables) and
// `"field.max" = [...]` (one quoted key) name the same key.
void collect_axes(const toml::table& table, const std::string& prefix, const std::string& where,
                  std::vector<Axis>& axes) {
  for (const auto& [name, node] : table) {
    const std::string key =
        prefix.empty() ? std::string(name.str()) : fmt::format("{}.{}", prefix, name.str());
    if (const auto* sub = node.as_table()) {
      collect_axes(*sub, key, where, axes);
      continue;
    }
    const auto* list = node.as_array();
    if (list == nullptr || list->empty()) {
      throw ConfigError(fmt::format(
          "{}.\"{}\" = {}: must be a non-empty list of the values to sweep, e.g. [0.1, 0.2]", where,
          key, toml_value_text(node)));
    }
    // The key must be one `--set` accepts (checked with a placeholder value).
    const std::string problem = config::override_syntax_error(key + "=0");
    if (!problem.empty()) {
      throw ConfigError(fmt::format("{}.\"{}\": not a valid key: {}", where, key,
                                    problem.substr(problem.find(": ") + 2)));
    }
    const auto& begin = node.source().begin;
    axes.push_back({key, list, {begin.line, begin.column}});
  }
}

std::vector<Axis> read_axes(const toml::table& sweep, std::string_view name) {
  const std::string where = fmt::format("sweep.{}", name);
  const toml::node* node = sweep.get(name);
  if (node == nullptr) return {};
  const auto* table = node->as_table();
  if (table == nullptr) {
    throw ConfigError(
        fmt::format("{} = {}: must be a table of lists, e.g. {} = {{ \"field.max\" = [0.1, 0.2] }}",
                    where, toml_value_text(*node), where));
  }
  std::vector<Axis> axes;
  collect_axes(*table, "", where, axes);
  if (axes.empty()) {
    throw ConfigError(fmt::format("{} = {{}}: names no key to sweep", where));
  }
  std::stable_sort(axes.begin(), axes.end(),
                   [](const Axis& a, const Axis& b) { return a.position < b.position; });
  return axes;
}

}  // namespace

bool has_sweep(const toml::table& root) { return root.contains("sweep"); }

std::string toml_value_text(const toml::node& node) {
  if (const auto* v = node.as_integer()) return std::to_string(v->get());
  if (const auto* v = node.as_floating_point()) return float_text(v->get());
  if (const auto* v = node.as_boolean()) return v->get() ? "true" : "false";
  if (const auto* v = node.as_string()) return config::toml_string_literal(v->get());
  if (const auto* array = node.as_array()) {
    std::string text = "[";
    for (std::size_t i = 0; i < array->size(); ++i) {
      text += (i == 0 ? "" : ", ") + toml_value_text(*array->get(i));
    }
    return text + "]";
  }
  if (const auto* table = node.as_table()) {
    std::string text = "{";
    bool first = true;
    for (const auto& [name, value] : *table) {
      const std::string_view key = name.str();
      text += fmt::format("{}{} = {}", first ? "" : ", ",
                          is_bare_key(key) ? std::string(key) : config::toml_string_literal(key),
                          toml_value_text(value));
      first = false;
    }
    return text + "}";
  }
  std::ostringstream out;  // dates and times
  node.visit([&](const auto& n) { out << n; });
  return out.str();
}

SweepSpec expand_sweep(const toml::table& root) {
  const toml::node* node = root.get("sweep");
  const auto* sweep = node == nullptr ? nullptr : node->as_table();
  if (sweep == nullptr) {
    throw ConfigError("sweep: must be a table: [sweep] with product = {...} and/or zip = {...}");
  }
  for (const auto& [name, value] : *sweep) {
    if (name.str() != "product" && name.str() != "zip") {
      throw ConfigError(
          fmt::format("unknown key 'sweep.{}' in [sweep]; allowed keys: product, zip", name.str()));
    }
  }
  const std::vector<Axis> zip = read_axes(*sweep, "zip");
  const std::vector<Axis> product = read_axes(*sweep, "product");
  if (zip.empty() && product.empty()) {
    throw ConfigError("[sweep] sweeps nothing: give product = {...} and/or zip = {...}");
  }
  for (const Axis& a : zip) {
    if (a.values->size() != zip.front().values->size()) {
      throw ConfigError(fmt::format(
          R"(sweep.zip: the lists must have one length: "{}" has {} value(s), "{}" has {})",
          zip.front().key, zip.front().values->size(), a.key, a.values->size()));
    }
  }

  SweepSpec spec;
  std::set<std::string> seen;
  for (const auto* axes : {&zip, &product}) {
    for (const Axis& a : *axes) {
      if (!seen.insert(a.key).second) {
        throw ConfigError(fmt::format(
            "sweep: \"{}\" is swept twice (in both zip and product); name each key once", a.key));
      }
      spec.keys.push_back(a.key);
    }
  }

  toml::table base = root;
  base.erase("sweep");
  spec.base_text = config::toml_text(base);

  // Mixed-radix counting: the zip axis (one digit) outermost, the last product list fastest.
  std::vector<std::size_t> radix;
  if (!zip.empty()) radix.push_back(zip.front().values->size());
  for (const Axis& a : product) radix.push_back(a.values->size());
  std::size_t count = 1;
  for (const std::size_t r : radix) count *= r;
  for (std::size_t index = 0; index < count; ++index) {
    std::vector<std::size_t> digit(radix.size());
    std::size_t rest = index;
    for (std::size_t d = radix.size(); d-- > 0;) {
      digit[d] = rest % radix[d];
      rest /= radix[d];
    }
    SweepPoint point;
    point.index = index;
    const auto add = [&](const Axis& a, std::size_t i) {
      point.values.push_back(toml_value_text(*a.values->get(i)));
      point.overrides.push_back(fmt::format("{}={}", a.key, point.values.back()));
    };
    std::size_t d = 0;
    if (!zip.empty()) {
      for (const Axis& a : zip) add(a, digit[0]);
      d = 1;
    }
    for (const Axis& a : product) add(a, digit[d++]);
    spec.points.push_back(std::move(point));
  }
  return spec;
}

}  // namespace mresim::sweep
