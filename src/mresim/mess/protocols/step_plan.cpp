#include "mresim/mess/protocols/step_plan.hpp"

namespace mresim::mess_protocol {

namespace mc = mresim::mess_config;

std::vector<double> load_values(const mc::MessSpec& spec) {
  if (spec.strain) return spec.strain->values;
  if (spec.stress) return spec.stress->values;
  return {0.0};
}

const char* load_unit(const mc::MessSpec& spec) {
  if (spec.stress) return "Pa";
  if (spec.strain) {
    const mc::LoadKind k = spec.strain->kind;
    return k == mc::LoadKind::shear || k == mc::LoadKind::torsion ? "rad" : "1";
  }
  return "1";
}

std::vector<StepSpec> plan_steps(const mc::MessSpec& spec) {
  const std::vector<double> loads = load_values(spec);
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

Eigen::Vector3d field_direction(const mc::MessSpec& spec) {
  for (const Eigen::Vector3d& b : spec.field.values) {
    if (b.norm() > 0.0) return b.normalized();
  }
  return Eigen::Vector3d::UnitZ();
}

}  // namespace mresim::mess_protocol
