#include "mresim/pair/ensemble.hpp"

#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <numeric>

#include "mresim/pair/parameter_map.hpp"

namespace mresim::pair {
namespace {

std::vector<PairSystem> members_for(double k, const std::vector<double>& separations) {
  std::vector<PairSystem> members;
  for (double s0 : separations) {
    PairSystem p;
    p.springs = {SpringModel::single, k, 0.0, s0};
    p.penalty = OverlapPenalty::tanh_default(1.5e-6);
    members.push_back(p);
  }
  return members;
}

std::vector<double> fig35_separations() {
  std::vector<double> s;
  for (int i = 0; i <= 49; ++i) s.push_back(3.2e-6 + 0.2e-6 * i);  // 3.2 ... 13.0 um
  return s;
}

TEST(GaussianWeights, AreNormalisedAndPeakAtTheMean) {
  const std::vector<double> s = fig35_separations();
  const std::vector<double> w = gaussian_weights(s, 4.8e-6, 6.5e-6);
  EXPECT_NEAR(std::accumulate(w.begin(), w.end(), 0.0), 1.0, 1e-14);
  EXPECT_EQ(std::max_element(w.begin(), w.end()) - w.begin(), 8);  // S0 = 4.8 um
}

// Claim C10, Fig. 3.5: the peak of the loop widening falls as k rises.
TEST(Figure35, PeakLoopWideningFallsWithStiffness) {
  const std::vector<double> s = fig35_separations();
  const std::vector<double> w = gaussian_weights(s, 4.8e-6, 6.5e-6);
  SweepOptions sweep;
  sweep.b_step = 0.02;
  double previous_peak = 2.0;
  for (double k : {9e-3, 9e-2, 9e-1}) {
    const EnsembleResult r = ensemble_average(members_for(k, s), w, sweep);
    const LoopWidening widening = loop_widening(r.average);
    const std::vector<double> smooth = five_point_average(widening.widening);
    const double peak = *std::max_element(smooth.begin(), smooth.end());
    EXPECT_LT(peak, previous_peak) << k;
    EXPECT_GE(peak, 0.0);
    previous_peak = peak;
  }
  EXPECT_GT(previous_peak, -1e-12);
}

TEST(LoopWidening, IsZeroForAReversibleLoop) {
  MagnetizationLoop loop;
  SweepOptions sweep;
  sweep.b_max = 0.1;
  for (const SweepPoint& p : sweep_points(sweep)) {
    loop.field.push_back(p.step_index * sweep.b_step);
    loop.branch.push_back(p.branch);
    loop.magnetization.push_back(std::tanh(5.0 * loop.field.back()));
  }
  const LoopWidening w = loop_widening(loop);
  EXPECT_EQ(w.field.size(), 11u);
  for (double x : w.widening) EXPECT_EQ(x, 0.0);
  const std::vector<double> chi = differential_susceptibility(loop, false);
  // Centred difference of tanh(5B) at B = 0.05 on the initial branch.
  EXPECT_NEAR(chi[5], (std::tanh(0.3) - std::tanh(0.2)) / 0.02, 1e-12);
}

TEST(FivePointAverage, ShrinksTheWindowAtTheEnds) {
  const std::vector<double> v{1, 2, 3, 4, 5, 6};
  const std::vector<double> a = five_point_average(v);
  EXPECT_DOUBLE_EQ(a[0], 2.0);  // (1+2+3)/3
  EXPECT_DOUBLE_EQ(a[2], 3.0);  // (1..5)/5
  EXPECT_DOUBLE_EQ(a[5], 5.0);  // (4+5+6)/3
}

// Results must not depend on the number of threads.
TEST(CriticalFieldMap, IsIdenticalForOneAndTwoThreads) {
  auto build = [](std::size_t row, std::size_t col) {
    MapPointSetup setup;
    setup.system.springs = {SpringModel::single, 1e-2 * (1.0 + 2.0 * static_cast<double>(row)), 0.0,
                            4e-6 + 2.5e-6 * static_cast<double>(col)};
    setup.sweep.b_step = 0.02;
    return setup;
  };
  const int saved = omp_get_max_threads();
  omp_set_num_threads(1);
  const CriticalFieldGrid one = map_critical_fields(3, 4, build, {});
  omp_set_num_threads(2);
  const CriticalFieldGrid two = map_critical_fields(3, 4, build, {});
  omp_set_num_threads(saved);
  int hysteretic = 0;
  for (std::size_t i = 0; i < one.fields.size(); ++i) {
    EXPECT_EQ(one.fields[i].hysteresis, two.fields[i].hysteresis);
    EXPECT_EQ(one.fields[i].hc1, two.fields[i].hc1);
    EXPECT_EQ(one.fields[i].hc2, two.fields[i].hc2);
    hysteretic += one.fields[i].hysteresis;
  }
  EXPECT_GT(hysteretic, 0);
  EXPECT_LT(hysteretic, 12);
}

}  // namespace
}  // namespace mresim::pair
