#include "mresim/pair/ensemble.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <stdexcept>

#include "mresim/core/parallel_exceptions.hpp"

namespace mresim::pair {

std::vector<double> gaussian_weights(const std::vector<double>& separations, double mean,
                                     double standard_deviation) {
  std::vector<double> w;
  w.reserve(separations.size());
  for (double s : separations) {
    const double z = (s - mean) / standard_deviation;
    w.push_back(std::exp(-0.5 * z * z));
  }
  const double total = std::accumulate(w.begin(), w.end(), 0.0);
  for (double& x : w) x /= total;
  return w;
}

MagnetizationLoop magnetization_loop(const HysteresisLoop& loop) {
  MagnetizationLoop out;
  const Eigen::Vector3d direction = field_direction(loop.options.theta_h_deg);
  for (const PairState& s : loop.states) {
    out.field.push_back(s.field);
    out.branch.push_back(s.branch);
    out.magnetization.push_back(s.magnetization_along(direction));
  }
  return out;
}

EnsembleResult ensemble_average(const std::vector<PairSystem>& members,
                                const std::vector<double>& weights, const SweepOptions& sweep) {
  if (members.size() != weights.size() || members.empty()) {
    throw std::invalid_argument("ensemble_average: need one weight per member");
  }
  EnsembleResult result;
  result.members.resize(members.size());
  const auto count = static_cast<long>(members.size());
  ParallelExceptions errors;
#pragma omp parallel for schedule(dynamic, 1)
  for (long i = 0; i < count; ++i) {
    errors.run([&] {
      result.members[static_cast<std::size_t>(i)] =
          magnetization_loop(run_hysteresis(members[static_cast<std::size_t>(i)], sweep));
    });
  }
  errors.rethrow();
  result.average = result.members.front();
  std::fill(result.average.magnetization.begin(), result.average.magnetization.end(), 0.0);
  for (std::size_t i = 0; i < members.size(); ++i) {
    for (std::size_t j = 0; j < result.average.magnetization.size(); ++j) {
      result.average.magnetization[j] += weights[i] * result.members[i].magnetization[j];
    }
  }
  return result;
}

LoopWidening loop_widening(const MagnetizationLoop& loop) {
  // Match the descending (1) and final ascending (2) branches by field on the sweep grid.
  std::map<long, double> descending;
  const double step = loop.field.size() > 1 ? std::abs(loop.field[1] - loop.field[0]) : 1.0;
  auto key = [&](double b) { return std::lround(b / step); };
  for (std::size_t i = 0; i < loop.field.size(); ++i) {
    // The descent starts at the turning point +B_max, stored as the last point of branch 0.
    const bool turning_point =
        i + 1 < loop.field.size() && loop.branch[i] == 0 && loop.branch[i + 1] == 1;
    if ((loop.branch[i] == 1 || turning_point) && loop.field[i] >= 0.0) {
      descending[key(loop.field[i])] = loop.magnetization[i];
    }
  }
  LoopWidening out;
  for (std::size_t i = 0; i < loop.field.size(); ++i) {
    if (loop.branch[i] != 2 || loop.field[i] < 0.0) continue;
    auto d = descending.find(key(loop.field[i]));
    if (d == descending.end()) continue;
    out.field.push_back(loop.field[i]);
    out.widening.push_back(d->second - loop.magnetization[i]);
  }
  return out;
}

std::vector<double> five_point_average(const std::vector<double>& values) {
  std::vector<double> out(values.size());
  const auto n = static_cast<long>(values.size());
  for (long i = 0; i < n; ++i) {
    const long lo = std::max(0L, i - 2);
    const long hi = std::min(n - 1, i + 2);
    double sum = 0.0;
    for (long j = lo; j <= hi; ++j) sum += values[static_cast<std::size_t>(j)];
    out[static_cast<std::size_t>(i)] = sum / static_cast<double>(hi - lo + 1);
  }
  return out;
}

std::vector<double> differential_susceptibility(const MagnetizationLoop& loop,
                                                bool five_point_smoothing) {
  std::vector<double> out(loop.field.size(), 0.0);
  std::size_t begin = 0;
  while (begin < loop.field.size()) {
    std::size_t end = begin;
    while (end < loop.field.size() && loop.branch[end] == loop.branch[begin]) ++end;
    // Include the turning point that ends the previous branch so each branch starts there.
    const std::size_t from = begin > 0 ? begin - 1 : begin;
    std::vector<double> slope;
    for (std::size_t i = from; i < end; ++i) {
      const std::size_t a = i > from ? i - 1 : i;
      const std::size_t b = i + 1 < end ? i + 1 : i;
      const double db = loop.field[b] - loop.field[a];
      slope.push_back(db != 0.0 ? (loop.magnetization[b] - loop.magnetization[a]) / db : 0.0);
    }
    if (five_point_smoothing) slope = five_point_average(slope);
    for (std::size_t i = begin; i < end; ++i) out[i] = slope[i - from];
    begin = end;
  }
  return out;
}

}  // namespace mresim::pair
