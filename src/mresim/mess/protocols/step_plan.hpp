#pragma once

// The relaxation steps of a 3D run (Section 4.2.7; docs/original-code.md#step-order), as the
// run's protocol plans them (protocol.hpp): one per applied field for hysteresis and
// magnetostriction; for strain and stress runs an outer loop over the load values and an inner
// loop over the fields, step n = load_index x F + field_index (F fields).

#include <Eigen/Core>
#include <cstddef>
#include <vector>

#include "mresim/mess/run_file/mess_spec.hpp"

namespace mresim::mess_protocol {

struct StepSpec {
  std::size_t index = 0;
  std::size_t field_index = 0;
  std::size_t load_index = 0;
  Eigen::Vector3d field = Eigen::Vector3d::Zero();  // B_ext = mu0 H_ext, T
  double load_value = 0.0;  // strain (rad or 1) or stress (Pa) as stored in the spec; 0 otherwise
};

std::vector<StepSpec> plan_steps(const mess_config::MessSpec& spec);

// The load values of the run's protocol (the strain or stress values; {0} without a load).
std::vector<double> load_values(const mess_config::MessSpec& spec);

// The unit of the load values: "rad" (shear, torsion), "1" (tension, compression), "Pa"
// (stress); "1" for the protocols without a load.
const char* load_unit(const mess_config::MessSpec& spec);

// The direction the run's fields are measured along (Fig. 4.4's field axis): the unit vector
// of the first non-zero field, +z if all are zero.
Eigen::Vector3d field_direction(const mess_config::MessSpec& spec);

}  // namespace mresim::mess_protocol
