// Where a strain run's steps start (solver.load_step_start, protocols/load_step_start.hpp): the
// scaled-down Fig. 4.14 shear run (Phi = 3 %, seed profile) through strains 0 ... 0.1 rad at
// three fields, from the previous strain's state as it is ("previous", the original's start),
// from the strain secant ("secant", the prediction without the previous fields' corrections)
// and from the corrected prediction ("extrapolated", the default), in one run. Prints per start
// the iterations, evaluations and CPU time of the strained steps, the ratios against the
// default, and how far apart the runs' results are.
//
//   ./build/strain_start_bench [--order N] [--steps K] [--repeats R]
//
// --order: the discretization order n_d (default 5: 52,200 nodes, where the default minimiser
// uses the multilevel preconditioner); --steps: strain values after 0 (default 5); --repeats:
// runs of each start, in turn, the fastest CPU time kept (default 1). One thread per run unless
// OMP_NUM_THREADS says otherwise.
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

// The largest differences of two runs' steps, and the starts the second one took.
void print_differences(const char* name, const Run& reference, const Run& run) {
  double centres = 0.0;
  double magnetization = 0.0;
  double energy = 0.0;
  std::vector<std::string> starts;
  for (std::size_t i = 0; i < reference.records.size(); ++i) {
    const mp::StepRecord& a = reference.records[i];
    const mp::StepRecord& b = run.records[i];
    centres = std::max(centres, (a.centres - b.centres).cwiseAbs().maxCoeff());
    magnetization =
        std::max(magnetization, (a.magnetization - b.magnetization).cwiseAbs().maxCoeff());
    energy = std::max(
        energy, std::abs(a.energies.total() - b.energies.total()) / std::abs(a.energies.total()));
    if (std::find(starts.begin(), starts.end(), b.start) == starts.end()) starts.push_back(b.start);
  }
  std::printf(
      "  %-12s against previous: centres %.2e m, M %.2e A/m, total energy %.2e relative; "
      "starts:",
      name, centres, magnetization, energy);
  for (const std::string& s : starts) std::printf(" %s", s.c_str());
  std::printf("\n");
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

  const std::vector<std::string> names = {"previous", "secant", "extrapolated"};
  std::vector<Run> runs(names.size());
  for (int k = 0; k < repeats; ++k) {
    for (std::size_t i = 0; i < names.size(); ++i) {
      Run r = run(names[i], order, steps);
      if (r.cpu < runs[i].cpu) runs[i] = std::move(r);
    }
  }
  std::printf(
      "Fig. 4.14 shear (small), n_d = %d: %lld nodes, 3 fields x %d strain steps to 0.1 rad\n",
      order, static_cast<long long>(runs[0].nodes), steps);
  const Run& best = runs.back();
  for (std::size_t i = 0; i < names.size(); ++i) {
    const Run& r = runs[i];
    std::printf(
        "  %-12s strained steps: %6lld iterations, %6lld evaluations, CPU %8.2f s; against "
        "extrapolated: iterations %.2fx, CPU %.2fx\n",
        names[i].c_str(), static_cast<long long>(r.iterations),
        static_cast<long long>(r.evaluations), r.cpu,
        static_cast<double>(r.iterations) / static_cast<double>(best.iterations), r.cpu / best.cpu);
  }
  for (std::size_t i = 1; i < names.size(); ++i) {
    print_differences(names[i].c_str(), runs[0], runs[i]);
  }
  return 0;
}
