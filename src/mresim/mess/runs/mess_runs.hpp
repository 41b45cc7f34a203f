#pragma once

// The run type of a 3D protocol: every protocol registered with mess_protocol::ProtocolRegistrar
// (protocols/protocol.hpp) becomes the [run] type of the same name through this function, so no
// list of the 3D run types exists anywhere.

#include <string>

#include "mresim/app/run_type.hpp"

namespace mresim::mess_runs {

// A run type whose plan reads the 3D run file (read_mess_spec) for the protocol `name`, checks
// its memory, describes it for `mresim info` and runs it with checkpoints (runs/mess_runs.cpp).
app::RunType mess_run_type(const std::string& name, const std::string& summary);

}  // namespace mresim::mess_runs
