#include "mresim/mess/protocols/protocol.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>

#include "mresim/mess/runs/mess_runs.hpp"

namespace mresim::mess_protocol {

namespace mc = mresim::mess_config;

namespace {

// A function-local static: the registrars of the protocol files run during static
// initialisation in an unspecified order (as app/run_type.cpp's registry).
std::vector<ProtocolType>& registry() {
  static std::vector<ProtocolType> types;
  return types;
}

std::string joined(const std::vector<std::string>& names) {
  std::string out;
  for (const std::string& n : names) out += (out.empty() ? "" : ", ") + n;
  return out;
}

}  // namespace

std::vector<StepSpec> Protocol::plan_steps(const mc::MessSpec& spec) const {
  const std::vector<double> loads = load_values();
  const std::size_t fields = spec.field.values.size();
  std::vector<StepSpec> steps;
  steps.reserve(loads.size() * fields);
  for (std::size_t l = 0; l < loads.size(); ++l) {
    for (std::size_t f = 0; f < fields; ++f) {
      StepSpec s;
      s.index = steps.size();
      s.field_index = f;
      s.load_index = l;
      s.field = spec.field.values[f];
      s.load_value = loads[l];
      steps.push_back(s);
    }
  }
  return steps;
}

double Protocol::measured_strain(const lattice::Lattice& /*lattice*/, const StepSpec& /*step*/,
                                 const Eigen::Matrix3Xd& /*positions*/,
                                 const Eigen::Matrix3Xd& /*zero_load*/) const {
  return 0.0;
}

void Protocol::check_scales(const config::TableReader& /*root*/, const mc::MessSpec& /*spec*/,
                            double /*top*/, double /*elastic*/) const {}

void Protocol::describe(const mc::MessSpec& /*spec*/, app::InfoReport& /*report*/) const {}

void register_protocol(ProtocolType type) {
  auto& types = registry();
  const auto same = [&](const ProtocolType& t) { return t.name == type.name; };
  if (std::any_of(types.begin(), types.end(), same)) {
    // Static initialisation: an exception here could not be caught anywhere.
    std::fprintf(stderr, "mresim: internal error: protocol '%s' is registered twice\n",
                 type.name.c_str());
    std::abort();
  }
  // The run type of the same name runs this protocol (runs/mess_runs.cpp).
  app::register_run_type(mess_runs::mess_run_type(type.name, type.summary));
  const auto position = std::lower_bound(
      types.begin(), types.end(), type, [](const ProtocolType& a, const ProtocolType& b) {
        return a.order != b.order ? a.order < b.order : a.name < b.name;
      });
  types.insert(position, std::move(type));
}

const std::vector<ProtocolType>& protocol_types() { return registry(); }

std::vector<std::string> protocol_names() {
  std::vector<std::string> names;
  for (const ProtocolType& t : registry()) names.push_back(t.name);
  return names;
}

const ProtocolType& find_protocol(std::string_view name) {
  for (const ProtocolType& t : registry()) {
    if (t.name == name) return t;
  }
  throw std::invalid_argument(
      fmt::format("'{}' is not a 3D protocol (registered: {})", name, joined(protocol_names())));
}

std::shared_ptr<const Protocol> read_protocol(const config::TableReader& root,
                                              std::string_view name) {
  const ProtocolType& own = find_protocol(name);
  std::shared_ptr<const Protocol> protocol;
  // Tables in registry order; this protocol's are read where its first one comes.
  for (const ProtocolType& t : registry()) {
    for (const std::string& table : t.tables) {
      if (t.name == own.name) {
        if (!protocol) protocol = own.read(root);
      } else if (root.has(table) &&
                 std::find(own.tables.begin(), own.tables.end(), table) == own.tables.end()) {
        root.fail(table, root.value_text(table),
                  fmt::format(R"(only read by [run] type = "{}" (this is "{}"))", t.name, name));
      }
    }
  }
  if (!protocol) protocol = own.read(root);
  return protocol;
}

}  // namespace mresim::mess_protocol
