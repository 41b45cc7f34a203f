// Relaxation of the 3D model (MESS): the fast minimisers against the dissertation's damped
// leapfrog, on the same problems, in the same run (docs/mess-solvers.md). Each method runs with
// its own default convergence criteria (minimiser: max force 1e-6 k_eff l_e; leapfrog: the
// original's float32 rule, twice in a row, at least 4 rounds of 5000 steps); the summary prints
// the wall-time ratios, the force evaluations, and how far apart the final states are.
//
//   ./build/mess_relax_bench
//   ./build/mess_relax_bench --benchmark_filter='BM_Relax/0/'   (first problem only)
#include <benchmark/benchmark.h>

#include <cstdio>
#include <map>
#include <string>

#include "mresim/core/constants.hpp"
#include "mresim/mess/lattice/lattice.hpp"
#include "mresim/mess/profile/model_profile.hpp"
#include "mresim/mess/protocols/loading.hpp"
#include "mresim/mess/solvers/leapfrog.hpp"
#include "mresim/mess/solvers/minimiser.hpp"

namespace {

namespace mess = mresim::mess;
namespace lat = mresim::lattice;

enum Method { lbfgs = 0, fire = 1, leapfrog = 2 };
const char* kMethodNames[] = {"lbfgs", "fire", "leapfrog"};

struct Problem {
  const char* name;
  const mess::ModelProfile& profile;
  int discretization_order;
  std::array<int, 3> cells;
  std::vector<std::array<int, 3>> centres;  // centre cells
  Eigen::Vector3d field_tesla;
  double time_step;  // leapfrog, t_c (n_d = 2 needs < 5e-3, docs/original-code.md#time-integration)
};

// Two particles on the z axis of a mirror-symmetric box, all faces held (the hysteresis
// boundary condition), field along z. Centres more than R (2 chi0/3)^(1/3) = 5.4 um apart:
// closer pairs are unstable even at zero field (docs/magnetization-3d.md), collapse into WCA
// contact, and the squeezed polymer between them buckles, so that different methods may end in
// different (mirror-image) states.
const Problem kProblems[] = {
    {"n_d=2, 12x12x24 nodes, S = 7.2 um, physical, 0.1 T",
     mess::model_profile("physical"),
     2,
     {11, 11, 23},
     {{5, 5, 5}, {5, 5, 17}},
     {0.0, 0.0, 0.1},
     4e-3},
    {"n_d=2, same, seed profile",
     mess::model_profile("seed"),
     2,
     {11, 11, 23},
     {{5, 5, 5}, {5, 5, 17}},
     {0.0, 0.0, 0.1},
     4e-3},
    {"n_d=3, 14x14x29 nodes, S = 6.4 um, physical, 50 mT",
     mess::model_profile("physical"),
     3,
     {13, 13, 28},
     {{6, 6, 6}, {6, 6, 21}},
     {0.0, 0.0, 0.05},
     5e-3},
};

mess::MessSystem make_system(const Problem& p) {
  lat::LatticeSpec spec;
  p.profile.apply_to(spec);
  spec.discretization_order = p.discretization_order;
  const double l_e = lat::element_length(spec.particle_radius, p.discretization_order);
  lat::ByHandPlacement placement;
  placement.box.lengths = Eigen::Vector3d(p.cells[0], p.cells[1], p.cells[2]) * l_e;
  for (const auto& c : p.centres) {
    placement.positions.emplace_back((c[0] + 0.5) * l_e, (c[1] + 0.5) * l_e, (c[2] + 0.5) * l_e);
  }
  spec.placement = placement;
  mess::MessSystem sys =
      mess::MessSystem::make(lat::build_lattice(spec), p.field_tesla / mresim::kMu0, p.profile);
  // The hysteresis runs' boundary condition: all six faces held.
  sys.set_constraints(
      mresim::mess_protocol::hysteresis_load(sys.lattice(), sys.lattice().positions).constraints);
  return sys;
}

struct Outcome {
  bool converged = false;
  std::int64_t evaluations = 0;
  Eigen::Matrix3Xd positions;
  double separation = 0.0;  // l_e
};

Outcome relax(const Problem& p, Method method) {
  mess::MessSystem sys = make_system(p);
  Outcome o;
  if (method == leapfrog) {
    mess::LeapfrogOptions opt = p.profile.leapfrog_options();
    opt.time_step = p.time_step;
    const mess::LeapfrogResult r = mess::relax_leapfrog(sys, opt);
    o.converged = r.converged;
    o.evaluations = r.steps + 1;
  } else {
    mess::MinimiserOptions opt;
    opt.method = method == lbfgs ? mess::MinimiserMethod::lbfgs : mess::MinimiserMethod::fire;
    const mess::MinimiserResult r = mess::minimise(sys, opt);
    o.converged = r.converged;
    o.evaluations = r.evaluations;
  }
  o.positions = sys.positions() / sys.length_scale();
  const Eigen::Matrix3Xd c = sys.particle_centres();
  o.separation = (c.col(1) - c.col(0)).norm() / sys.length_scale();
  return o;
}

std::map<std::pair<int, int>, Outcome> g_outcomes;  // (problem, method)

void BM_Relax(benchmark::State& state) {
  const auto problem = static_cast<int>(state.range(0));
  const auto method = static_cast<Method>(state.range(1));
  Outcome o;
  for ([[maybe_unused]] auto _ : state) o = relax(kProblems[problem], method);
  state.counters["evaluations"] = static_cast<double>(o.evaluations);
  state.counters["converged"] = o.converged ? 1 : 0;
  state.SetLabel(std::string(kProblems[problem].name) + ", " + kMethodNames[method]);
  g_outcomes[{problem, static_cast<int>(method)}] = std::move(o);
}
BENCHMARK(BM_Relax)
    ->ArgsProduct({{0, 1, 2}, {lbfgs, fire, leapfrog}})
    ->Iterations(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

class RatioReporter : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    for (const Run& r : runs) seconds_[r.benchmark_name()] = r.GetAdjustedRealTime() / 1e3;
    ConsoleReporter::ReportRuns(runs);
  }
  void Summarise() const {
    std::printf("\n== Summary (wall time, this run; states in units of l_e) ==\n");
    for (int p = 0; p < 3; ++p) {
      const auto* const lf = find(p, leapfrog);
      if (!lf) continue;
      std::printf("%s\n", kProblems[p].name);
      for (const Method m : {lbfgs, fire}) {
        const auto* const t = find(p, m);
        if (!t) continue;
        const Outcome& a = g_outcomes.at({p, m});
        const Outcome& b = g_outcomes.at({p, leapfrog});
        std::printf(
            "  leapfrog %.3f s (%lld evaluations) / %-5s %.3f s (%lld evaluations) = %.0fx; "
            "max |node difference| %.2e, separations %.6f vs %.6f; converged %d/%d\n",
            *lf, static_cast<long long>(b.evaluations), kMethodNames[m], *t,
            static_cast<long long>(a.evaluations), *lf / *t,
            (a.positions - b.positions).cwiseAbs().maxCoeff(), a.separation, b.separation,
            a.converged, b.converged);
      }
    }
    std::printf(
        "  (M is solved tightly, atol = rtol = 1e-12, in every method; with the original's "
        "band, [solver.magnetization]\n   tolerance = \"original\", the states differed by up "
        "to ~1e-3 l_e, each method ending somewhere in that band)\n");
  }

 private:
  const double* find(int problem, Method m) const {
    const std::string name = "BM_Relax/" + std::to_string(problem) + "/" +
                             std::to_string(static_cast<int>(m)) + "/iterations:1/real_time";
    const auto it = seconds_.find(name);
    return it == seconds_.end() ? nullptr : &it->second;
  }
  std::map<std::string, double> seconds_;
};

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  RatioReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  reporter.Summarise();
  benchmark::Shutdown();
  return 0;
}
