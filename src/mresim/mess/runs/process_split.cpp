#include "mresim/mess/runs/process_split.hpp"

#include <fmt/format.h>

#include <memory>

#include "mresim/config/config_error.hpp"
#include "mresim/mess/distributed/distributed_evaluator.hpp"
#include "mresim/mess/distributed/distributed_system.hpp"
#include "mresim/mess/distributed/mpi_job.hpp"

namespace mresim::mess_protocol {

namespace mc = mresim::mess_config;

bool split_over_processes(ProtocolRunner& runner) {
  if (mess::mpi_job().size == 1) return false;
  runner.set_distributed(std::make_shared<mess::DistributedEvaluator>(MPI_COMM_WORLD));
  return true;
}

bool method_splits_over_processes(mc::SolverMethod method) {
  return method == mc::SolverMethod::minimiser || method == mc::SolverMethod::lbfgs;
}

void refuse_what_cannot_split(const mc::MessSpec& spec) {
  if (mess::mpi_job().size == 1) return;
  if (!method_splits_over_processes(spec.solver.method)) {
    throw config::ConfigError(fmt::format(
        "solver.method = \"{}\": under mpirun with more than one process only \"minimiser\" "
        "and \"lbfgs\" split a relaxation over the processes (docs/mpi.md); run this file "
        "without mpirun",
        mc::solver_method_name(spec.solver.method)));
  }
  for (const mess::TermSpec& term : spec.terms) {
    if (!mess::DistributedSystem::supports(term.name)) {
      throw config::ConfigError(
          fmt::format("[terms.{}]: this energy term cannot be evaluated over MPI processes yet "
                      "(docs/mpi.md); run this file without mpirun",
                      term.name));
    }
  }
}

}  // namespace mresim::mess_protocol
