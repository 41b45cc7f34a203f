#include "mresim/magnetism/preisach.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

#include "mresim/magnetism/portable_random.hpp"

namespace mresim::magnetism {

namespace {

void validate(const PreisachParameters& p) {
  if (p.relay_count < 1) throw std::invalid_argument("PreisachModel: relay_count must be >= 1");
  const bool finite = std::isfinite(p.switch_up_mean_t) && std::isfinite(p.switch_down_mean_t) &&
                      std::isfinite(p.switch_sd_t) && std::isfinite(p.weight_mean) &&
                      std::isfinite(p.weight_sd) && std::isfinite(p.weight_min);
  if (!finite) throw std::invalid_argument("PreisachModel: parameters must be finite");
  if (p.switch_sd_t < 0.0) throw std::invalid_argument("PreisachModel: switch_sd_t must be >= 0");
  if (p.weight_sd < 0.0) throw std::invalid_argument("PreisachModel: weight_sd must be >= 0");
  if (!(p.weight_min > 0.0)) throw std::invalid_argument("PreisachModel: weight_min must be > 0");
}

}  // namespace

PreisachModel::PreisachModel(const PreisachParameters& params) {
  validate(params);
  const auto n = static_cast<std::size_t>(params.relay_count);
  alpha_.resize(n);
  beta_.resize(n);
  weights_.resize(n);
  states_.resize(n);

  // Relay population of Fig. 1.5; draw order per relay: alpha, beta, weight.
  PortableNormal random(params.seed);
  double weight_sum = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    double alpha = random.normal(params.switch_up_mean_t, params.switch_sd_t);
    double beta = random.normal(params.switch_down_mean_t, params.switch_sd_t);
    if (alpha < beta) std::swap(alpha, beta);  // a relay needs alpha >= beta
    alpha_[i] = alpha;
    beta_[i] = beta;
    weights_[i] = std::max(random.normal(params.weight_mean, params.weight_sd), params.weight_min);
    weight_sum += weights_[i];
  }
  for (double& w : weights_) w /= weight_sum;  // all relays up <=> M/Ms = 1

  // Demagnetized initial state (see header): forced relays first, then bistable ones
  // balanced against the running magnetization.
  double running = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    if (alpha_[i] <= 0.0) {
      states_[i] = 1;
    } else if (beta_[i] >= 0.0) {
      states_[i] = -1;
    } else {
      continue;
    }
    running += weights_[i] * states_[i];
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (!(beta_[i] < 0.0 && 0.0 < alpha_[i])) continue;
    if (running > 0.0) {
      states_[i] = -1;
    } else if (running < 0.0) {
      states_[i] = 1;
    } else {
      states_[i] = random.coin() ? 1 : -1;
    }
    running += weights_[i] * states_[i];
  }
  magnetization_ = sum_magnetization();
}

double PreisachModel::apply_field(double b_tesla) {
  const std::size_t n = weights_.size();
  for (std::size_t i = 0; i < n; ++i) {
    if (b_tesla >= alpha_[i]) {
      states_[i] = 1;
    } else if (b_tesla <= beta_[i]) {
      states_[i] = -1;
    }
  }
  magnetization_ = sum_magnetization();
  return magnetization_;
}

double PreisachModel::sum_magnetization() const {
  // Summed afresh in index order each time, so the result depends only on the states.
  double m = 0.0;
  for (std::size_t i = 0; i < weights_.size(); ++i) m += weights_[i] * states_[i];
  return m;
}

MagnetizationCurve preisach_loop(const PreisachParameters& params, double b_max, double b_step) {
  const std::vector<SweepPoint> sweep = major_loop_sweep(b_max, b_step);
  PreisachModel model(params);
  MagnetizationCurve curve;
  curve.b_tesla.reserve(sweep.size());
  curve.m_over_ms.reserve(sweep.size());
  curve.branch.reserve(sweep.size());
  for (const SweepPoint& point : sweep) {
    curve.b_tesla.push_back(point.b_tesla);
    curve.m_over_ms.push_back(model.apply_field(point.b_tesla));
    curve.branch.push_back(point.branch);
  }
  return curve;
}

}  // namespace mresim::magnetism
