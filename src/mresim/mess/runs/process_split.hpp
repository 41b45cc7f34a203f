#pragma once

// One 3D relaxation split over the processes of `mpirun -np P` (P > 1, docs/mpi.md), as the
// three commands that relax 3D steps use it: `mresim run`/`resume` (mess_runs.cpp), `mresim
// extend` (restart/extend_plan.cpp) and `mresim rerun` (restart/rerun_plan.cpp). Every process
// runs the same steps; their evaluations are split, so their states stay identical.

#include "mresim/mess/protocols/protocol_runner.hpp"
#include "mresim/mess/run_file/mess_spec.hpp"

namespace mresim::mess_protocol {

// Under `mpirun -np P` with P > 1: `runner`'s relaxations split their evaluations over all
// processes of the job. Returns whether it does (false on one process, `runner` unchanged).
bool split_over_processes(ProtocolRunner& runner);

// Whether a relaxation with `method` splits over the processes ("minimiser" and "lbfgs").
bool method_splits_over_processes(mess_config::SolverMethod method);

// Under `mpirun -np P` with P > 1: throws config::ConfigError, naming the key, for what a
// relaxation of `spec` cannot split over the processes yet (a solver method other than
// "minimiser" and "lbfgs", an energy term without a distributed form). Does nothing on one
// process.
void refuse_what_cannot_split(const mess_config::MessSpec& spec);

}  // namespace mresim::mess_protocol
