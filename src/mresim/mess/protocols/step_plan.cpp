#include "mresim/mess/protocols/step_plan.hpp"

#include "mresim/mess/protocols/protocol.hpp"

namespace mresim::mess_protocol {

namespace mc = mresim::mess_config;

// The protocol decides (protocol.hpp); these keep the callers free of it.
std::vector<double> load_values(const mc::MessSpec& spec) { return spec.protocol->load_values(); }

const char* load_unit(const mc::MessSpec& spec) { return spec.protocol->load_unit(); }

std::vector<StepSpec> plan_steps(const mc::MessSpec& spec) {
  return spec.protocol->plan_steps(spec);
}

Eigen::Vector3d field_direction(const mc::MessSpec& spec) {
  for (const Eigen::Vector3d& b : spec.field.values) {
    if (b.norm() > 0.0) return b.normalized();
  }
  return Eigen::Vector3d::UnitZ();
}

}  // namespace mresim::mess_protocol
