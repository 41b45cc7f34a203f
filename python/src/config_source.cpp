#include "config_source.hpp"

#include <fmt/format.h>
#include <toml++/toml.h>

#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "mresim/config/config_error.hpp"
#include "mresim/config/overrides.hpp"

namespace py = pybind11;

namespace mresim::python {

namespace {

std::unique_ptr<toml::node> toml_node_of(const py::handle& value, const std::string& key);

toml::table toml_table_of(const py::dict& tables, const std::string& prefix) {
  toml::table out;
  for (const auto& [name, value] : tables) {
    if (!py::isinstance<py::str>(name)) {
      throw config::ConfigError(fmt::format("run-file key {}{}: keys must be strings", prefix,
                                            py::repr(name).cast<std::string>()));
    }
    const auto key = name.cast<std::string>();
    auto node = toml_node_of(value, prefix + key);
    out.insert_or_assign(key, std::move(*node));
  }
  return out;
}

std::unique_ptr<toml::node> toml_node_of(const py::handle& value, const std::string& key) {
  // numpy scalars and arrays: their Python equivalents (np.float64 is a float already, but
  // np.int64, np.bool_ and arrays are not).
  if (py::hasattr(value, "tolist") && !py::isinstance<py::str>(value)) {
    return toml_node_of(value.attr("tolist")(), key);
  }
  if (py::isinstance<py::bool_>(value)) {
    return std::make_unique<toml::value<bool>>(value.cast<bool>());
  }
  if (py::isinstance<py::int_>(value)) {
    try {
      return std::make_unique<toml::value<std::int64_t>>(value.cast<std::int64_t>());
    } catch (const py::cast_error&) {
      throw config::ConfigError(fmt::format("{} = {}: TOML integers are 64-bit", key,
                                            py::str(value).cast<std::string>()));
    }
  }
  if (py::isinstance<py::float_>(value)) {
    return std::make_unique<toml::value<double>>(value.cast<double>());
  }
  if (py::isinstance<py::str>(value)) {
    return std::make_unique<toml::value<std::string>>(value.cast<std::string>());
  }
  if (py::isinstance<py::dict>(value)) {
    return std::make_unique<toml::table>(toml_table_of(value.cast<py::dict>(), key + "."));
  }
  if (py::isinstance<py::list>(value) || py::isinstance<py::tuple>(value)) {
    toml::array array;
    std::size_t index = 0;
    for (const py::handle item : value) {
      auto node = toml_node_of(item, fmt::format("{}[{}]", key, index++));
      array.push_back(std::move(*node));
    }
    return std::make_unique<toml::array>(std::move(array));
  }
  throw config::ConfigError(fmt::format(
      "{} = {}: not a run-file value (numbers, strings, booleans, lists and dicts only)", key,
      py::repr(value).cast<std::string>()));
}

}  // namespace

std::string toml_text_of_dict(const py::dict& tables) {
  return config::toml_text(toml_table_of(tables, ""));
}

config::TableReader read_config(const py::handle& source,
                                const std::vector<std::string>& overrides) {
  if (py::isinstance<py::dict>(source)) {
    return config::TableReader::parse_string(toml_text_of_dict(source.cast<py::dict>()), "<dict>",
                                             overrides);
  }
  if (py::isinstance<py::str>(source)) {
    return config::TableReader::parse_string(source.cast<std::string>(), "<string>", overrides);
  }
  if (py::hasattr(source, "__fspath__")) {
    const auto path = py::module_::import("os").attr("fspath")(source).cast<std::string>();
    return config::TableReader::parse_file(path, overrides);
  }
  throw py::type_error(
      "a run file is a dict of tables, TOML text (str) or a path (pathlib.Path), not " +
      py::str(py::type::of(source)).cast<std::string>());
}

}  // namespace mresim::python
