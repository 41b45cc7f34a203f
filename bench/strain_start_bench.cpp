// Where a strain run's steps start (solver.load_step_start, protocols/load_step_start.hpp): the
// scaled-down Fig. 4.14 shear run (Phi = 3 %, seed profile) through strains 0 ... 0.1 rad at
// three fields, once from the previous strain's state as it is ("previous", the original's
// start) and once from the predicted state ("extrapolated", the default), in one run. Prints per
// start the iterations, evaluations and CPU time of the strained steps, the ratios, and how far
// apart the two runs' results are.
//
//   ./build/strain_start_bench [--order N] [--steps K] [--repeats R]
//
// --order: the discretization order n_d (default 5: 52,200 nodes, where the default minimiser
// uses the multilevel preconditioner); --steps: strain values after 0 (default 5); --repeats:
// runs of each start, alternating, the fastest CPU time kept (default 1). One thread per run
// unless OMP_NUM_THREADS says otherwise.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <limits>
#include <string>
#include <vector>

#include "mresim/config/table_reader.hpp"
#include "mresim/mess/protocols/protocol_runner.hpp"
#include "mresim/mess/run_file/mess_spec.hpp"

namespace {

namespace mp = mresim::mess_protocol;

double cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

struct Run {
  std::vector<mp::StepRecord> records;
  double cpu = std::numeric_limits<double>::infinity();  // the strained steps', s
  std::int64_t iterations = 0;                           // strained steps
  std::int64_t evaluations = 0;                          // strained steps
  std::int64_t nodes = 0;
};

Run run(const std::string& start, int order, int steps) {
  const std::string path =
      std::string(MRESIM_SOURCE_DIR) + "/examples/chapter4/small/fig4_14_shear_phi3_small.toml";
  const std::vector<std::string> overrides = {
      fmt::format("model.discretization_order={}", order), "strain.max=0.1",
      fmt::format("strain.steps={}", steps), fmt::format("solver.load_step_start=\"{}\"", start)};
  const mresim::mess_config::MessSpec spec = mresim::mess_config::read_mess_run_file(
      mresim::config::TableReader::parse_file(path, overrides));
  mp::ProtocolRunner runner(spec);
  mp::ProtocolState state = runner.initial_state();
  Run r;
  r.nodes = runner.system().node_count();
  double cpu = 0.0;
  while (state.next_step < runner.steps().size()) {
    const double cpu0 = cpu_seconds();
    const mp::StepRecord& record = runner.run_next_step(state);
    if (record.step.load_index > 0) {
      cpu += cpu_seconds() - cpu0;
      r.iterations += record.iterations;
      r.evaluations += record.evaluations;
    }
    if (!record.converged) {
      std::fprintf(stderr, "step %zu did not converge (%s)\n", record.step.index,
                   record.status.c_str());
      std::exit(1);
    }
  }
  r.cpu = cpu;
  r.records = state.records;
  return r;
}

int read_option(int argc, char** argv, const std::string& key, int fallback) {
  for (int k = 1; k + 1 < argc; ++k) {
    if (argv[k] == key) return std::max(1, std::atoi(argv[k + 1]));
  }
  return fallback;
}

}  // namespace

int main(int argc, char** argv) {
  for (int k = 1; k < argc; k += 2) {
    const std::string key = argv[k];
    if ((key != "--order" && key != "--steps" && key != "--repeats") || k + 1 >= argc) {
      std::fprintf(stderr, "unknown option %s (--order N, --steps K, --repeats R)\n", argv[k]);
      return 2;
    }
  }
  const int order = read_option(argc, argv, "--order", 5);
  const int steps = read_option(argc, argv, "--steps", 5);
  const int repeats = read_option(argc, argv, "--repeats", 1);
  double load[3] = {};
  if (getloadavg(load, 3) > 0) std::printf("load average at start: %.2f\n", load[0]);

  Run previous;
  Run extrapolated;
  for (int k = 0; k < repeats; ++k) {
    Run a = run("previous", order, steps);
    Run b = run("extrapolated", order, steps);
    if (a.cpu < previous.cpu) previous = std::move(a);
    if (b.cpu < extrapolated.cpu) extrapolated = std::move(b);
  }
  std::printf(
      "Fig. 4.14 shear (small), n_d = %d: %lld nodes, 3 fields x %d strain steps to 0.1 rad\n",
      order, static_cast<long long>(previous.nodes), steps);
  for (const auto& [name, r] :
       {std::pair<const char*, const Run&>{"previous", previous}, {"extrapolated", extrapolated}}) {
    std::printf("  %-12s strained steps: %6lld iterations, %6lld evaluations, CPU %8.2f s\n", name,
                static_cast<long long>(r.iterations), static_cast<long long>(r.evaluations), r.cpu);
  }
  std::printf(
      "  previous / extrapolated: iterations %.2fx, evaluations %.2fx, CPU %.2fx\n",
      static_cast<double>(previous.iterations) / static_cast<double>(extrapolated.iterations),
      static_cast<double>(previous.evaluations) / static_cast<double>(extrapolated.evaluations),
      previous.cpu / extrapolated.cpu);

  double centres = 0.0;
  double magnetization = 0.0;
  double energy = 0.0;
  std::vector<std::string> starts;
  for (std::size_t i = 0; i < previous.records.size(); ++i) {
    const mp::StepRecord& a = previous.records[i];
    const mp::StepRecord& b = extrapolated.records[i];
    centres = std::max(centres, (a.centres - b.centres).cwiseAbs().maxCoeff());
    magnetization =
        std::max(magnetization, (a.magnetization - b.magnetization).cwiseAbs().maxCoeff());
    energy = std::max(
        energy, std::abs(a.energies.total() - b.energies.total()) / std::abs(a.energies.total()));
    if (std::find(starts.begin(), starts.end(), b.start) == starts.end()) starts.push_back(b.start);
  }
  std::printf("  largest differences: centres %.2e m, M %.2e A/m, total energy %.2e relative\n",
              centres, magnetization, energy);
  std::printf("  extrapolated run's starts:");
  for (const std::string& s : starts) std::printf(" %s", s.c_str());
  std::printf("\n");
  return 0;
}
