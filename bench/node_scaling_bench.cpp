// Two choices of the multilevel preconditioner's finest level, in one run (solvers/
// preconditioner.hpp): how it scales the polymer's nodes (solver.node_scaling: the inverse of
// each node's 3 x 3 stiffness block, "blocks", the default, against the inverse of its diagonal,
// "diagonal", the scaling before), or with --compare contact_gap whether it solves the polymer
// between particles in contact exactly (solver.contact_gap: "exact", the default, against
// "none", the preconditioner before; solvers/contact_gap_blocks.hpp), or with --compare
// preconditioner_reuse whether a step keeps the preconditioner built at an earlier step's start
// (solver.preconditioner_reuse: 0.3 lattice spacings, the default, against 0.1, the default
// before; solvers/preconditioner_cache.hpp; also prints how many steps kept it). Problem: the
// Fig. 4.11 pair's full box (the example's run file) at a lower discretization order, fields 0, 5,
// ..., 35 mT upwards: the pair snaps into contact on the way (seed profile; 79,054 nodes at the
// default n_d = 3, where the default minimiser uses the multilevel preconditioner). Prints per step
// the iterations with each choice, then the totals, the evaluations, the CPU time, the ratios, and
// how far apart the two runs' states are (per step: the largest difference of a centre
// coordinate and of M, the total energy's relative one). Exit status 1 if a step does not
// converge or the two choices take identical paths (the setting would not have reached the
// preconditioner).
//
//   ./build/node_scaling_bench [--order N] [--steps K] [--repeats R]
//                              [--compare contact_gap | preconditioner_reuse]
//
// --order: the discretization order n_d (default 3); --steps: field steps after 0 mT, 5 mT
// apart (default 7); --repeats: runs of each choice, alternating, the fastest CPU time kept
// (default 1). One thread per run unless OMP_NUM_THREADS says otherwise.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "mresim/mess/protocols/protocol_runner.hpp"
#include "protocol_bench_options.hpp"

namespace {

namespace mp = mresim::mess_protocol;

using Run = mresim::bench::ProtocolRun;

// solver.<key> = value (a TOML value: a string in quotes, or a number).
Run run(const std::string& key, const std::string& value, int order, int steps) {
  std::string label = value;
  std::erase(label, '"');
  return mresim::bench::run_protocol(
      "examples/chapter4/fig4_11_pair_large_box_S6_5um.toml",
      {fmt::format("model.discretization_order={}", order),
       fmt::format("field.max={}", 0.005 * steps), fmt::format("field.steps={}", steps),
       "field.sequence=\"up\"", "output.node_positions=false", "output.checkpoint_every=0",
       fmt::format("solver.{}={}", key, value)},
      label, [](const mp::StepRecord&) { return true; });
}

// Steps that kept the multilevel preconditioner of an earlier step.
long long kept_steps(const Run& r) {
  return std::count_if(r.records.begin(), r.records.end(),
                       [](const mp::StepRecord& s) { return s.preconditioner == "kept"; });
}

using Values = std::pair<std::string, std::string>;

// The earlier choice of solver.<key> first, then the default (TOML values); nothing for an
// unknown key.
std::optional<Values> values_of(const std::string& key) {
  if (key == "node_scaling") return Values{"\"diagonal\"", "\"blocks\""};
  if (key == "contact_gap") return Values{"\"none\"", "\"exact\""};
  if (key == "preconditioner_reuse") return Values{"0.1", "0.3"};
  return std::nullopt;
}

// The pair's separation (um).
double separation(const mp::StepRecord& r) {
  return 1e6 * (r.centres.col(1) - r.centres.col(0)).norm();
}

// Prints the largest differences between the two runs' states; true if they took identical
// paths.
bool print_largest_differences(const Run& earlier, const Run& chosen) {
  double centres = 0.0;
  double separations = 0.0;
  double magnetization = 0.0;
  double energy = 0.0;
  bool identical = true;
  for (std::size_t i = 0; i < earlier.records.size(); ++i) {
    const mp::StepRecord& a = earlier.records[i];
    const mp::StepRecord& b = chosen.records[i];
    centres = std::max(centres, (a.centres - b.centres).cwiseAbs().maxCoeff());
    separations = std::max(separations, std::abs(separation(a) - separation(b)) * 1e-6);
    magnetization =
        std::max(magnetization, (a.magnetization - b.magnetization).cwiseAbs().maxCoeff());
    if (std::abs(a.energies.total()) > 0.0) {
      energy = std::max(
          energy, std::abs(a.energies.total() - b.energies.total()) / std::abs(a.energies.total()));
    }
    identical = identical && a.iterations == b.iterations && a.centres == b.centres;
  }
  std::printf(
      "  largest differences: centres %.2e m, separations %.2e m, M %.2e A/m, total energy %.2e "
      "relative\n",
      centres, separations, magnetization, energy);
  return identical;
}

}  // namespace

int main(int argc, char** argv) {
  // --compare contact_gap switches the setting; the rest are the protocol benches' options.
  std::string key = "node_scaling";
  std::vector<char*> rest = {argv[0]};
  for (int k = 1; k < argc; ++k) {
    if (std::string(argv[k]) == "--compare" && k + 1 < argc) {
      key = argv[++k];
    } else {
      rest.push_back(argv[k]);
    }
  }
  const std::optional<Values> chosen_values = values_of(key);
  if (!chosen_values) {
    std::fprintf(stderr, "--compare %s: one of node_scaling, contact_gap, preconditioner_reuse\n",
                 key.c_str());
    return 2;
  }
  const Values& values = *chosen_values;
  Values labels = values;  // for the table: without the quotes
  std::erase(labels.first, '"');
  std::erase(labels.second, '"');
  const auto options =
      mresim::bench::parse_protocol_bench_options(static_cast<int>(rest.size()), rest.data(), 3, 7);
  if (!options) return 2;
  const int order = options->order;
  const int steps = options->steps;
  const int repeats = options->repeats;
  double load[3] = {};
  if (getloadavg(load, 3) > 0) std::printf("load average at start: %.2f\n", load[0]);

  Run earlier;  // the choice before (values.first)
  Run chosen;   // the default (values.second)
  for (int k = 0; k < repeats; ++k) {
    Run a = run(key, values.first, order, steps);
    Run b = run(key, values.second, order, steps);
    if (a.cpu < earlier.cpu) earlier = std::move(a);
    if (b.cpu < chosen.cpu) chosen = std::move(b);
  }
  std::printf("Fig. 4.11 pair, full box, n_d = %d: %lld nodes, fields 0 ... %g mT upwards\n", order,
              static_cast<long long>(earlier.nodes), 5.0 * steps);
  std::printf("solver.%s: %s against %s\n", key.c_str(), labels.first.c_str(),
              labels.second.c_str());
  std::printf("  %4s %10s %9s %9s %28s %20s %12s %12s %12s\n", "step", "field (mT)",
              labels.first.c_str(), labels.second.c_str(), "separation (um), each",
              "pair angle (deg)", "centres (m)", "M (A/m)", "energy");
  // The pair axis's angle from the field's axis (z).
  const auto angle = [](const mp::StepRecord& r) {
    const Eigen::Vector3d d = r.centres.col(1) - r.centres.col(0);
    return std::acos(std::min(1.0, std::abs(d.z()) / d.norm())) * 180.0 / M_PI;
  };
  for (std::size_t i = 0; i < earlier.records.size(); ++i) {
    const mp::StepRecord& a = earlier.records[i];
    const mp::StepRecord& b = chosen.records[i];
    const double total = std::abs(a.energies.total());
    std::printf("  %4zu %10.1f %9lld %9lld %13.5f / %.5f %9.4f / %.4f %12.2e %12.2e %12.2e\n", i,
                1e3 * a.step.field.norm(), static_cast<long long>(a.iterations),
                static_cast<long long>(b.iterations), separation(a), separation(b), angle(a),
                angle(b), (a.centres - b.centres).cwiseAbs().maxCoeff(),
                (a.magnetization - b.magnetization).cwiseAbs().maxCoeff(),
                total > 0.0 ? std::abs(a.energies.total() - b.energies.total()) / total : 0.0);
  }
  for (const auto& [name, r] : {std::pair<const std::string&, const Run&>{labels.first, earlier},
                                {labels.second, chosen}}) {
    std::printf(
        "  %-9s %6lld iterations, %6lld evaluations, CPU %8.2f s, %lld steps kept the "
        "preconditioner\n",
        name.c_str(), static_cast<long long>(r.iterations), static_cast<long long>(r.evaluations),
        r.cpu, kept_steps(r));
  }
  std::printf("  %s / %s: iterations %.2fx, evaluations %.2fx, CPU %.2fx\n", labels.first.c_str(),
              labels.second.c_str(),
              static_cast<double>(earlier.iterations) / static_cast<double>(chosen.iterations),
              static_cast<double>(earlier.evaluations) / static_cast<double>(chosen.evaluations),
              earlier.cpu / chosen.cpu);

  const bool identical = print_largest_differences(earlier, chosen);
  if (identical) {
    std::fprintf(stderr, "the two choices took identical paths: the setting had no effect\n");
    return 1;
  }
  return 0;
}
