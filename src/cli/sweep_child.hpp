#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace mresim::cli {

// The path of the running `mresim` executable (/proc/self/exe), so that the points of a sweep
// run the very build that planned them.
std::filesystem::path own_executable();

// Runs `args` (args[0] the program's path) with stdin from /dev/null and stdout and stderr
// appended to `log`, and waits for it. Returns its exit status, 128 + the signal that ended it,
// or 127 if it could not be started.
//
// The child gets this process's environment without the variables by which OpenMPI, PMIx and
// PMI tell a process that it is a rank of an MPI job (OMPI_*, PMIX_*, PMI_*): a point launched
// from a rank of `mpirun -np N mresim sweep` is a separate single-process run, and with them it
// would try to join the parent's job.
int run_child(const std::vector<std::string>& args, const std::filesystem::path& log);

// Whether `name=value` is one of those variables.
bool is_mpi_launch_variable(const std::string& entry);

}  // namespace mresim::cli
