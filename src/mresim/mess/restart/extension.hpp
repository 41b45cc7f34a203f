#pragma once

// How an extended protocol relates to the computed one (`mresim extend`): the planned steps of
// both run files compared, so that the check does not depend on how the sequence was written
// (field.max and steps, magnitudes, values; loop or up).
//
// Two steps are the same when their field and load indices are equal and their fields and load
// values agree to 1e-12 relative (max/steps arithmetic of a longer sequence may differ in the
// last bit from the shorter one's).

#include <cstdint>
#include <string>
#include <vector>

#include "mresim/mess/protocols/step_plan.hpp"

namespace mresim::mess_protocol {

struct Extension {
  std::size_t shared = 0;              // leading steps the two plans have in common
  std::vector<std::int64_t> added;     // new steps whose field and load no computed step had
  std::vector<std::int64_t> replaced;  // computed steps at or after `shared`
};

// Compares the plans. Throws config::ConfigError (naming `what`, the overrides) when the new
// plan drops a field and load value that a computed step had (it would change the computed
// steps, not extend them) or adds no step.
Extension plan_extension(const std::vector<StepSpec>& computed,
                         const std::vector<StepSpec>& extended, const std::string& what);

bool same_step(const StepSpec& a, const StepSpec& b);

}  // namespace mresim::mess_protocol
