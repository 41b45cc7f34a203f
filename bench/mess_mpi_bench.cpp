// Speed-up of the distributed elastic terms (src/mresim/mess/distributed/) from 1 to P MPI
// processes, measured in one run:
//
//   mpirun -np 2 ./build/mess_mpi_bench                 (Fig. 4.11 pair, 1 thread per process)
//   mpirun -np 2 ./build/mess_mpi_bench --system fig4_25_helix --repeats 10 --threads 1
//   mpirun -np 2 ./build/mess_mpi_bench --relax-steps 2  (also the run's first two steps)
//
// (OpenMPI binds each process to a core when there are at most two: with --threads above 1
// add --bind-to none, or the threads share one core.)
//
// The system is built from its run file exactly as `mresim run` builds it (on every process:
// the set-up is not distributed yet, docs/mpi.md), every free node displaced at random by up
// to 0.05 l_e so that every spring and cell is strained. Timed, best of the repeats:
//  - the single-process kernels (ElasticTerms::evaluate) on process 0, for reference;
//  - DistributedElastic::evaluate (energy + gradient) on process 0 alone (a communicator of
//    one), then on all P processes (the time of the slowest, between barriers);
// and printed: the times, nodes per second, the 1 -> P speed-up, and whether the distributed
// gradient is bitwise the single-process one (it must be). With --relax-steps N, also the run's
// first N steps relaxed as `mresim run` relaxes them (L-BFGS, the run file's settings): on
// process 0 alone without MPI, on process 0 over a communicator of one, and on all P processes
// (mpirun -np P mresim run), with the speed-up and the largest difference of the final
// particle centres from the single-process run.
#include <omp.h>
#include <petscvec.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <thread>

#include "mresim/config/table_reader.hpp"
#include "mresim/mess/distributed/distributed_elastic.hpp"
#include "mresim/mess/distributed/distributed_evaluator.hpp"
#include "mresim/mess/protocols/protocol_runner.hpp"
#include "mresim/mess/run_file/mess_spec.hpp"
#include "mresim/mess/solvers/amg_preconditioner.hpp"
#include "mresim/mess/terms/elastic_terms.hpp"

namespace {

namespace mess = mresim::mess;

struct Options {
  std::string system = "fig4_11";
  int repeats = 5;
  int threads = 1;      // OpenMP threads per process
  int relax_steps = 0;  // > 0: also time the run's first steps as `mresim run` relaxes them
};

const char* run_file_of(const std::string& system) {
  if (system == "fig4_11") return "examples/chapter4/fig4_11_pair_large_box_S6_5um.toml";
  if (system == "fig4_25_helix") return "examples/chapter4/fig4_25_helix_R3_5um.toml";
  return nullptr;
}

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string key = argv[i];
    const std::string value = argv[i + 1];
    if (key == "--system") {
      o.system = value;
    } else if (key == "--repeats") {
      o.repeats = std::stoi(value);
    } else if (key == "--threads") {
      o.threads = std::stoi(value);
    } else if (key == "--relax-steps") {
      o.relax_steps = std::stoi(value);
    } else {
      std::fprintf(stderr, "mess_mpi_bench: unknown option %s\n", key.c_str());
      std::exit(2);
    }
  }
  if (run_file_of(o.system) == nullptr || o.repeats < 1 || o.threads < 1 || o.relax_steps < 0) {
    std::fprintf(stderr,
                 "mess_mpi_bench: --system must be fig4_11 or fig4_25_helix, --repeats and "
                 "--threads >= 1, --relax-steps >= 0\n");
    std::exit(2);
  }
  return o;
}

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// Best wall time of `repeats` collective evaluations on `comm` (the slowest process's).
double best_distributed_seconds(const mess::DistributedElastic& elastic, Vec x, Vec g,
                                MPI_Comm comm, int repeats) {
  double best = 1e300;
  for (int r = 0; r < repeats; ++r) {
    MPI_Barrier(comm);
    const auto start = std::chrono::steady_clock::now();
    (void)elastic.evaluate(x, g);
    double mine = seconds_since(start);
    double slowest = 0.0;
    MPI_Allreduce(&mine, &slowest, 1, MPI_DOUBLE, MPI_MAX, comm);
    best = std::min(best, slowest);
  }
  return best;
}

// Waits until every process of `comm` has called this, without spinning: OpenMPI's blocking
// calls poll at full speed, which would take a core from the process being timed alone.
void wait_quietly(MPI_Comm comm) {
  MPI_Request request = MPI_REQUEST_NULL;
  MPI_Ibarrier(comm, &request);
  int done = 0;
  while (MPI_Test(&request, &done, MPI_STATUS_IGNORE) == MPI_SUCCESS && done == 0) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
}

struct DistributedRun {
  double seconds = 0.0;
  bool bitwise = false;  // gradient == the single-process one (meaningful on process 0)
};

// Builds the decomposition on `comm` and times it; every process of `comm` calls this.
DistributedRun run_on(MPI_Comm comm, const mess::MessSystem& system, const Eigen::Matrix3Xd& x,
                      const Eigen::Matrix3Xd& expected, int repeats) {
  const mresim::lattice::Lattice& lattice = system.lattice();
  const mess::LatticeDecomposition decomposition(lattice.shape, comm);
  const mess::DistributedElastic elastic(lattice, decomposition,
                                         system.settings().elastic.volume_force_factor);
  Vec positions = decomposition.create_global_vector();
  Vec gradient = decomposition.create_global_vector();
  decomposition.scatter(x, positions);
  DistributedRun run;
  run.seconds = best_distributed_seconds(elastic, positions, gradient, comm, repeats);
  run.bitwise = decomposition.gather(gradient) == expected;
  (void)VecDestroy(&positions);
  (void)VecDestroy(&gradient);
  return run;
}

struct Relaxation {
  double seconds = 0.0;
  std::int64_t evaluations = 0;
  Eigen::Matrix3Xd centres;
};

// The run's first `steps` steps as `mresim run` relaxes them, evaluations split over `comm`
// (MPI_COMM_NULL: this process alone, no MPI); every process of `comm` calls this.
Relaxation relax(const mresim::mess_config::MessSpec& spec, int steps, MPI_Comm comm) {
  mresim::mess_protocol::ProtocolRunner runner(spec);
  if (comm != MPI_COMM_NULL)
    runner.set_distributed(std::make_shared<mess::DistributedEvaluator>(comm));
  mresim::mess_protocol::ProtocolState state = runner.initial_state();
  Relaxation r;
  const auto start = std::chrono::steady_clock::now();
  for (int k = 0; k < steps && state.next_step < runner.steps().size(); ++k) {
    r.evaluations += runner.run_next_step(state).evaluations;
  }
  r.seconds = seconds_since(start);
  r.centres = runner.system().particle_centres();
  return r;
}

// Relaxation times: this process alone without MPI, alone over a communicator of one, then all
// processes; printed by process 0 with the speed-up and how far apart the final centres are.
void time_relaxations(const mresim::mess_config::MessSpec& spec, int steps, int rank, int size) {
  Relaxation serial;
  Relaxation one;
  MPI_Comm alone = MPI_COMM_NULL;
  MPI_Comm_split(MPI_COMM_WORLD, rank == 0 ? 0 : MPI_UNDEFINED, 0, &alone);
  if (rank == 0) {
    serial = relax(spec, steps, MPI_COMM_NULL);
    one = relax(spec, steps, alone);
    MPI_Comm_free(&alone);
  }
  wait_quietly(MPI_COMM_WORLD);
  const Relaxation all = relax(spec, steps, MPI_COMM_WORLD);
  if (rank != 0) return;
  const auto apart = [&](const Relaxation& r) {
    return r.centres.cols() > 0 ? (r.centres - serial.centres).cwiseAbs().maxCoeff() : 0.0;
  };
  std::printf("  relaxation of the run's first %d steps (what mresim run does):\n", steps);
  std::printf("    one process, no MPI:      %8.2f s  %lld evaluations\n", serial.seconds,
              static_cast<long long>(serial.evaluations));
  std::printf("    distributed, 1 process:   %8.2f s  %lld evaluations  centres %.2e m apart\n",
              one.seconds, static_cast<long long>(one.evaluations), apart(one));
  std::printf("    distributed, %d processes: %8.2f s  %lld evaluations  centres %.2e m apart\n",
              size, all.seconds, static_cast<long long>(all.evaluations), apart(all));
  std::printf("    speed-up 1 -> %d processes: %.2fx (against no MPI: %.2fx)\n", size,
              one.seconds / all.seconds, serial.seconds / all.seconds);
}

}  // namespace

int main(int argc, char** argv) {
  const Options options = parse(argc, argv);
  mess::initialise_petsc();
  int rank = 0;
  int size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  omp_set_num_threads(options.threads);

  const std::string path = std::string(MRESIM_SOURCE_DIR) + "/" + run_file_of(options.system);
  const mresim::mess_config::MessSpec spec =
      mresim::mess_config::read_mess_run_file(mresim::config::TableReader::parse_file(path));
  const mresim::mess_protocol::ProtocolRunner runner(spec);
  const mess::MessSystem& system = runner.system();
  std::mt19937_64 random(20261203);  // the same strained state on every process
  std::uniform_real_distribution<double> jitter(-0.05, 0.05);
  Eigen::Matrix3Xd x = system.positions();
  for (Eigen::Index n = 0; n < x.cols(); ++n) {
    for (int a = 0; a < 3; ++a) x(a, n) += jitter(random) * system.length_scale();
  }
  mess::ElasticTermSettings settings;
  settings.volume_force_factor = system.settings().elastic.volume_force_factor;
  const mess::ElasticTerms serial(system.lattice(), settings);
  Eigen::Matrix3Xd expected(3, x.cols());
  double serial_seconds = 1e300;
  for (int r = 0; r < options.repeats; ++r) {
    const auto start = std::chrono::steady_clock::now();
    (void)serial.evaluate(system.lattice(), x, &expected);
    serial_seconds = std::min(serial_seconds, seconds_since(start));
  }

  // Process 0 alone, then all processes.
  MPI_Comm alone = MPI_COMM_NULL;
  MPI_Comm_split(MPI_COMM_WORLD, rank == 0 ? 0 : MPI_UNDEFINED, 0, &alone);
  DistributedRun one;
  if (rank == 0) {
    one = run_on(alone, system, x, expected, options.repeats);
    MPI_Comm_free(&alone);
  }
  wait_quietly(MPI_COMM_WORLD);
  const DistributedRun all = run_on(MPI_COMM_WORLD, system, x, expected, options.repeats);

  if (rank == 0) {
    const auto nodes = static_cast<double>(system.node_count());
    double load[1] = {0.0};
    (void)getloadavg(load, 1);
    std::printf("%s: %lld nodes, %d OpenMP thread(s) per process, best of %d, load average %.2f\n",
                options.system.c_str(), static_cast<long long>(system.node_count()),
                options.threads, options.repeats, load[0]);
    std::printf("  single-process kernels (ElasticTerms):  %8.2f ms  %6.2f M nodes/s\n",
                1e3 * serial_seconds, nodes / serial_seconds / 1e6);
    std::printf(
        "  distributed, 1 process:                 %8.2f ms  %6.2f M nodes/s  gradient %s\n",
        1e3 * one.seconds, nodes / one.seconds / 1e6,
        one.bitwise ? "bitwise the single-process one" : "DIFFERS");
    std::printf(
        "  distributed, %d processes:               %8.2f ms  %6.2f M nodes/s  gradient %s\n", size,
        1e3 * all.seconds, nodes / all.seconds / 1e6,
        all.bitwise ? "bitwise the single-process one" : "DIFFERS");
    std::printf("  speed-up 1 -> %d processes: %.2fx\n", size, one.seconds / all.seconds);
  }
  if (options.relax_steps > 0) time_relaxations(spec, options.relax_steps, rank, size);
  return one.bitwise || rank != 0 ? (all.bitwise ? 0 : 1) : 1;
}
