#include "mresim/mess/run_file/array_reader.hpp"

#include <fmt/format.h>
#include <toml++/toml.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>

namespace mresim::mess_config {

using config::ConfigError;
using config::Range;
using config::TableReader;

namespace {

std::string unit_suffix(std::string_view unit) {
  return unit.empty() ? std::string{} : fmt::format(" ({})", unit);
}

// As TableReader writes values: shortest round-trip text, floats recognisable as floats.
std::string format_float(double x) {
  std::string text = fmt::format("{}", x);
  if (text.find_first_of(".eEni") == std::string::npos) text += ".0";
  return text;
}

std::string format_node(const toml::node& node) {
  if (const auto* s = node.as_string()) return fmt::format("\"{}\"", s->get());
  if (const auto* i = node.as_integer()) return fmt::format("{}", i->get());
  if (const auto* f = node.as_floating_point()) return format_float(f->get());
  if (const auto* b = node.as_boolean()) return b->get() ? "true" : "false";
  if (const auto* a = node.as_array()) {
    constexpr std::size_t kMaxShown = 6;
    std::string out = "[";
    for (std::size_t i = 0; i < a->size() && i < kMaxShown; ++i) {
      if (i > 0) out += ", ";
      out += format_node(*a->get(i));
    }
    if (a->size() > kMaxShown) out += ", ...";
    return out + "]";
  }
  if (node.is_table()) return "{...}";
  return "(date/time)";
}

[[noreturn]] void fail_at(const std::string& path, const toml::node& node, std::string_view what) {
  throw ConfigError(fmt::format("{} = {}: {}", path, format_node(node), what));
}

// The document parsed again, kept alive with the node found in it.
struct Found {
  toml::table root;
  const toml::node* node = nullptr;
};

// Marks `key` as known in `table` (whatever its type) and returns its node, or nullptr.
std::unique_ptr<Found> find(const TableReader& table, std::string_view key) {
  try {
    (void)table.optional_number(key, Range::any(), "");
  } catch (const ConfigError&) {
    // Present but not a number: it is known now, which is all this call is for.
  }
  if (!table.has(key)) return nullptr;
  auto found = std::make_unique<Found>();
  found->root =
      toml::parse(std::string_view(table.source_text()), std::string_view(table.source_name()));
  const toml::table* current = &found->root;
  const std::string& path = table.path();
  std::size_t begin = 0;
  while (!path.empty() && begin <= path.size()) {
    const std::size_t end = std::min(path.find('.', begin), path.size());
    std::string segment = path.substr(begin, end - begin);
    std::optional<std::size_t> index;
    if (const std::size_t bracket = segment.find('['); bracket != std::string::npos) {
      index = std::stoul(segment.substr(bracket + 1));
      segment.resize(bracket);
    }
    const toml::node* next = current->get(segment);
    if (next != nullptr && index) {
      const auto* array = next->as_array();
      next = array != nullptr ? array->get(*index) : nullptr;
    }
    current = next != nullptr ? next->as_table() : nullptr;
    if (current == nullptr) {
      throw std::logic_error(fmt::format("array_reader: no table [{}] in the document", path));
    }
    begin = end + 1;
  }
  found->node = current->get(key);
  return found;
}

double component(const toml::node& node, const std::string& path, const Range& range,
                 std::string_view unit) {
  double value = 0.0;
  if (const auto* i = node.as_integer()) {
    value = static_cast<double>(i->get());
  } else if (const auto* f = node.as_floating_point()) {
    value = f->get();
  } else {
    fail_at(path, node, fmt::format("expected a number{}", unit_suffix(unit)));
  }
  if (!std::isfinite(value)) {
    fail_at(path, node, fmt::format("expected a finite number{}", unit_suffix(unit)));
  }
  if (!range.contains(value)) {
    fail_at(path, node, fmt::format("{}{}", range.describe(), unit_suffix(unit)));
  }
  return value;
}

Eigen::Vector3d vector3(const toml::node& node, const std::string& path, const Range& range,
                        std::string_view unit) {
  const auto* array = node.as_array();
  if (array == nullptr || array->size() != 3) {
    fail_at(path, node, fmt::format("expected [x, y, z]{}", unit_suffix(unit)));
  }
  Eigen::Vector3d v;
  for (std::size_t a = 0; a < 3; ++a) {
    v[static_cast<Eigen::Index>(a)] =
        component(*array->get(a), fmt::format("{}[{}]", path, a), range, unit);
  }
  return v;
}

}  // namespace

std::string vector_text(const Eigen::Vector3d& v) {
  return fmt::format("[{}, {}, {}]", format_float(v[0]), format_float(v[1]), format_float(v[2]));
}

bool is_array(const TableReader& table, std::string_view key) {
  // TableReader writes arrays, and only arrays, with a leading '['.
  const std::string text = table.value_text(key);
  return !text.empty() && text.front() == '[';
}

std::optional<Eigen::Vector3d> optional_vector3(const TableReader& table, std::string_view key,
                                                const Range& range, std::string_view unit) {
  const auto found = find(table, key);
  if (!found) return std::nullopt;
  return vector3(*found->node, table.path(key), range, unit);
}

std::optional<std::vector<Eigen::Vector3d>> optional_vector3_list(const TableReader& table,
                                                                  std::string_view key,
                                                                  const Range& range,
                                                                  std::string_view unit,
                                                                  std::size_t min_size) {
  const auto found = find(table, key);
  if (!found) return std::nullopt;
  const std::string path = table.path(key);
  const auto* array = found->node->as_array();
  if (array == nullptr) {
    fail_at(path, *found->node,
            fmt::format("expected a list of [x, y, z] vectors{}", unit_suffix(unit)));
  }
  if (array->size() < min_size) {
    fail_at(path, *found->node,
            fmt::format("expected at least {} [x, y, z] vector{}{}", min_size,
                        min_size == 1 ? "" : "s", unit_suffix(unit)));
  }
  std::vector<Eigen::Vector3d> out;
  out.reserve(array->size());
  for (std::size_t i = 0; i < array->size(); ++i) {
    out.push_back(vector3(*array->get(i), fmt::format("{}[{}]", path, i), range, unit));
  }
  return out;
}

std::optional<std::array<long, 3>> optional_integer3(const TableReader& table, std::string_view key,
                                                     const Range& range) {
  const auto found = find(table, key);
  if (!found) return std::nullopt;
  const std::string path = table.path(key);
  const auto* array = found->node->as_array();
  if (array == nullptr || array->size() != 3) {
    fail_at(path, *found->node, "expected three integers [x, y, z]");
  }
  std::array<long, 3> out{};
  for (std::size_t a = 0; a < 3; ++a) {
    const toml::node& item = *array->get(a);
    const std::string item_path = fmt::format("{}[{}]", path, a);
    const auto* i = item.as_integer();
    if (i == nullptr) fail_at(item_path, item, "expected an integer");
    const auto value = static_cast<long>(i->get());
    if (!range.contains(static_cast<double>(value))) fail_at(item_path, item, range.describe());
    out[a] = value;
  }
  return out;
}

}  // namespace mresim::mess_config
