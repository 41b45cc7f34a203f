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
#include <string>
#include <vector>

#include "mresim/mess/protocols/protocol_runner.hpp"
#include "protocol_bench_options.hpp"

namespace {

namespace mp = mresim::mess_protocol;

using Run = mresim::bench::ProtocolRun;

// The strained steps' cost (load index > 0).
Run run(const std::string& start, int order, int steps) {
  return mresim::bench::run_protocol(
      "examples/chapter4/small/fig4_14_shear_phi3_small.toml",
      {fmt::format("model.discretization_order={}", order), "strain.max=0.1",
       fmt::format("strain.steps={}", steps), fmt::format("solver.load_step_start=\"{}\"", start)},
      start, [](const mp::StepRecord& record) { return record.step.load_index > 0; });
}

}  // namespace

int main(int argc, char** argv) {
  const auto options = mresim::bench::parse_protocol_bench_options(argc, argv, 5, 5);
  if (!options) return 2;
  const int order = options->order;
  const int steps = options->steps;
  const int repeats = options->repeats;
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
