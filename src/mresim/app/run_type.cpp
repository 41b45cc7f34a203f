#include "mresim/app/run_type.hpp"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>

#include "mresim/app/threads.hpp"

namespace mresim::app {

namespace {

// A function-local static: registrars in other translation units run during static
// initialisation, in an unspecified order, possibly before a namespace-scope vector would exist.
std::vector<RunType>& registry() {
  static std::vector<RunType> types;
  return types;
}

}  // namespace

void register_run_type(RunType type) {
  auto& types = registry();
  if (find_run_type(type.name) != nullptr) {
    // Static initialisation: an exception here could not be caught anywhere.
    std::fprintf(stderr, "mresim: internal error: run type '%s' is registered twice\n",
                 type.name.c_str());
    std::abort();
  }
  const auto position =
      std::lower_bound(types.begin(), types.end(), type.name,
                       [](const RunType& t, const std::string& name) { return t.name < name; });
  types.insert(position, std::move(type));
}

void RunPlan::participate(const std::filesystem::path& /*staging_dir*/) const {
  throw std::logic_error("RunPlan::participate: this run type does not split over processes");
}

const std::vector<RunType>& run_types() { return registry(); }

const RunType* find_run_type(std::string_view name) {
  for (const auto& t : registry()) {
    if (t.name == name) return &t;
  }
  return nullptr;
}

RunSettings read_run_settings(const config::TableReader& root) {
  std::vector<std::string> names;
  for (const auto& t : run_types()) names.push_back(t.name);
  if (names.empty()) throw std::runtime_error("this build of mresim contains no run types");

  const auto run = root.table("run");
  RunSettings settings;
  settings.type = run.choice("type", names);
  settings.title = run.string_or("title", "");
  settings.threads = run.integer_or("threads", 0, config::Range::any());
  if (settings.threads < 0 || settings.threads > max_threads()) {
    run.fail("threads", run.value_text("threads"), threads_allowed());
  }
  return settings;
}

std::unique_ptr<RunPlan> make_plan(const config::TableReader& root, std::string* run_type_name) {
  const RunSettings settings = read_run_settings(root);
  const RunType* type = find_run_type(settings.type);
  auto plan = type->make_plan(root);
  if (!plan) throw std::logic_error("run type '" + settings.type + "' returned no plan");
  // Only now is it known which keys the run type understands.
  root.reject_unknown_keys();
  if (run_type_name != nullptr) *run_type_name = settings.type;
  return plan;
}

}  // namespace mresim::app
