#include "mresim/mess/restart/restart_overrides.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <string_view>

#include "mresim/config/config_error.hpp"

namespace mresim::mess_protocol {

namespace {

// The keys that only say how far the field or load sequence goes.
constexpr std::array<std::string_view, 11> kExtendKeys = {
    "field.max",      "field.steps",  "field.magnitudes", "field.values",
    "field.sequence", "strain.max",   "strain.steps",     "strain.values",
    "stress.max",     "stress.steps", "stress.values"};

std::string extend_key_list() {
  std::string out;
  for (const std::string_view k : kExtendKeys) out += (out.empty() ? "" : ", ") + std::string(k);
  return out;
}

}  // namespace

std::string override_key(const std::string& argument) {
  return argument.substr(0, argument.find('='));
}

std::string overrides_text(const std::vector<std::string>& overrides) {
  std::string out;
  for (const std::string& o : overrides) out += (out.empty() ? "--set " : " --set ") + o;
  return out;
}

void check_extend_overrides(const std::vector<std::string>& overrides) {
  if (overrides.empty()) {
    throw config::ConfigError(
        "extend: no --set given; name the longer field or load sequence, e.g. --set "
        "field.max=0.1 --set field.steps=10");
  }
  for (const std::string& o : overrides) {
    const std::string key = override_key(o);
    if (std::find(kExtendKeys.begin(), kExtendKeys.end(), key) != kExtendKeys.end()) continue;
    const bool solver = key.rfind("solver.", 0) == 0;
    throw config::ConfigError(fmt::format(
        "extend --set {}: {} is not a key that lengthens the protocol; the computed steps would "
        "not belong to the extended run (allowed: {}){}",
        o, key, extend_key_list(),
        solver ? "; to relax a step with other solver settings use 'mresim rerun'"
               : "; a run with another system is a new run ('mresim run')"));
  }
}

void check_rerun_overrides(const std::vector<std::string>& overrides) {
  for (const std::string& o : overrides) {
    const std::string key = override_key(o);
    if (key.rfind("solver.", 0) == 0) continue;
    throw config::ConfigError(fmt::format(
        "rerun --set {}: {} is not a solver setting; rerun relaxes the same step of the same "
        "system again and accepts only solver.* keys (solver.method, solver.minimiser.*, "
        "solver.leapfrog.*, solver.magnetization.*)",
        o, key));
  }
}

}  // namespace mresim::mess_protocol
