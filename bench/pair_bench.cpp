// Two-dipole benchmarks (issue: one full +-1 T loop at 0.01 T steps; a 30 x 50 (k, S0) map at
// 0.01 T steps with critical fields refined to 1e-4 T). Each problem is solved by the default
// Newton relaxation and by the reference nonlinear conjugate gradients of Section 2.4, in the
// same run; the summary prints the ratios and checks that both reach the same states.
//
//   ./build/pair_bench                  (all)
//   ./build/pair_bench --benchmark_filter=Loop
#include <benchmark/benchmark.h>
#include <omp.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <string>

#include "mresim/pair/parameter_map.hpp"
#include "mresim/pair/stiffness.hpp"

namespace {

using namespace mresim::pair;

PairSystem fig22_pair() {
  PairSystem p;
  p.springs = {SpringModel::single, 4e-2, 0.0, 9e-6};
  p.penalty = OverlapPenalty::tanh_default(1.5e-6);
  return p;
}

PairSystem fig27_pair() {
  PairSystem p;
  const PuljizStiffness k = puljiz_stiffness(1375.0, 1.5e-6, 9e-6);
  p.springs = {SpringModel::three, k.k12, k.k0, 9e-6};
  p.penalty = OverlapPenalty::wca_default(1.5e-6);
  return p;
}

SweepOptions sweep_with(RelaxMethod method, double angle = 0.0) {
  SweepOptions s;  // +-1 T, 0.01 T steps
  s.theta_h_deg = angle;
  s.relax.method = method;
  if (method == RelaxMethod::conjugate_gradient) s.relax.max_iterations = 100000;
  return s;
}

// Largest distance between the states of two loops of the same sweep (m).
double max_difference(const HysteresisLoop& a, const HysteresisLoop& b) {
  double worst = 0.0;
  for (std::size_t i = 0; i < a.states.size(); ++i) {
    worst = std::max(worst, (a.states[i].separation - b.states[i].separation).norm());
  }
  return worst;
}

std::map<std::string, double> g_agreement;  // m, filled once per problem

void BM_Fig22Loop(benchmark::State& state) {
  const auto method = static_cast<RelaxMethod>(state.range(0));
  for ([[maybe_unused]] auto _ : state)
    benchmark::DoNotOptimize(run_hysteresis(fig22_pair(), sweep_with(method)));
  state.SetLabel(method == RelaxMethod::newton ? "newton" : "conjugate_gradient");
}
BENCHMARK(BM_Fig22Loop)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_Fig27Loop(benchmark::State& state) {
  const auto method = static_cast<RelaxMethod>(state.range(0));
  for ([[maybe_unused]] auto _ : state) {
    benchmark::DoNotOptimize(run_hysteresis(fig27_pair(), sweep_with(method, 10.0)));
  }
  state.SetLabel(method == RelaxMethod::newton ? "newton" : "conjugate_gradient");
}
BENCHMARK(BM_Fig27Loop)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();

// The Fig. 2.5 map: k log-spaced 1e-3 ... 0.9 N/m (30), S0 = 3.2 ... 13 um (50).
CriticalFieldGrid fig25_map(RelaxMethod method) {
  auto build = [method](std::size_t row, std::size_t col) {
    MapPointSetup s;
    s.system = fig22_pair();
    s.system.springs.k12 = 1e-3 * std::pow(900.0, static_cast<double>(row) / 29.0);
    s.system.springs.rest_separation = 3.2e-6 + 0.2e-6 * static_cast<double>(col);
    s.sweep = sweep_with(method);
    return s;
  };
  return map_critical_fields(30, 50, build, {});
}

void BM_Fig25Map(benchmark::State& state) {
  const auto method = static_cast<RelaxMethod>(state.range(0));
  const int threads = static_cast<int>(state.range(1));
  omp_set_num_threads(threads);
  int hysteretic = 0;
  for ([[maybe_unused]] auto _ : state) {
    const CriticalFieldGrid grid = fig25_map(method);
    hysteretic = 0;
    for (const CriticalFields& f : grid.fields) hysteretic += f.hysteresis;
  }
  state.counters["hysteretic_points"] = hysteretic;
  state.SetLabel(std::string(method == RelaxMethod::newton ? "newton" : "conjugate_gradient") +
                 ", " + std::to_string(threads) + " thread(s)");
}
BENCHMARK(BM_Fig25Map)
    ->Args({0, 1})
    ->Args({0, 2})
    ->Args({1, 2})
    ->Iterations(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// Collects wall times so the summary can print ratios measured in this run.
class RatioReporter : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    for (const Run& r : runs) seconds_[r.benchmark_name()] = r.GetAdjustedRealTime() / 1e3;
    ConsoleReporter::ReportRuns(runs);
  }
  void Summarise() const {
    std::printf("\n== Summary (wall time, this run) ==\n");
    ratio("Fig. 2.2 loop, +-1 T / 0.01 T", "BM_Fig22Loop/1/real_time", "BM_Fig22Loop/0/real_time");
    ratio("Fig. 2.7 loop (three springs, 10 deg)", "BM_Fig27Loop/1/real_time",
          "BM_Fig27Loop/0/real_time");
    ratio("Fig. 2.5 map 30 x 50, 2 threads", "BM_Fig25Map/1/2/iterations:1/real_time",
          "BM_Fig25Map/0/2/iterations:1/real_time");
    const auto one = seconds_.find("BM_Fig25Map/0/1/iterations:1/real_time");
    const auto two = seconds_.find("BM_Fig25Map/0/2/iterations:1/real_time");
    if (one != seconds_.end() && two != seconds_.end()) {
      std::printf(
          "  map, Newton: 1 thread %.3f s, 2 threads %.3f s (speed-up %.2fx); target for "
          "the whole map on 2 cores: < 1.5 s -> %s\n",
          one->second, two->second, one->second / two->second,
          two->second < 1.5 ? "met" : "NOT met");
    }
    for (const auto& [name, metres] : g_agreement) {
      std::printf("  agreement %-40s max |d_newton - d_cg| = %.3g m\n", name.c_str(), metres);
    }
  }

 private:
  void ratio(const char* what, const std::string& slow, const std::string& fast) const {
    const auto s = seconds_.find(slow);
    const auto f = seconds_.find(fast);
    if (s == seconds_.end() || f == seconds_.end()) return;
    std::printf("  %-40s conjugate gradients %.4f s / Newton %.4f s = %.1fx\n", what, s->second,
                f->second, s->second / f->second);
  }
  std::map<std::string, double> seconds_;
};

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  // Both methods must land on the same states, or the timing comparison means nothing.
  g_agreement["Fig. 2.2 loop"] =
      max_difference(run_hysteresis(fig22_pair(), sweep_with(RelaxMethod::newton)),
                     run_hysteresis(fig22_pair(), sweep_with(RelaxMethod::conjugate_gradient)));
  g_agreement["Fig. 2.7 loop"] = max_difference(
      run_hysteresis(fig27_pair(), sweep_with(RelaxMethod::newton, 10.0)),
      run_hysteresis(fig27_pair(), sweep_with(RelaxMethod::conjugate_gradient, 10.0)));
  RatioReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  reporter.Summarise();
  benchmark::Shutdown();
  return 0;
}
