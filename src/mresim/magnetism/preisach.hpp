#pragma once

// Classical Preisach model of hysteresis with rectangular relays, as used for the simulated
// hysteresis loop of a magnetically hard ferromagnet in dissertation Fig. 1.5 (Section 1.3.3,
// ref. [37]): 1e5 relays, up/down switching fields normally distributed around +0.35 T and
// -0.35 T with standard deviation 0.2 T, relay weights normally distributed around 5 with
// standard deviation 2.5, clipped to a minimum of 0.01 and normalized.

#include <cstddef>
#include <cstdint>
#include <vector>

#include "mresim/magnetism/magnetization_curve.hpp"

namespace mresim::magnetism {

// Defaults are the Fig. 1.5 values. Fields are applied fields B = mu0 H in tesla.
struct PreisachParameters {
  int relay_count = 100000;
  double switch_up_mean_t = 0.35;     // mean of the up-switching field alpha
  double switch_down_mean_t = -0.35;  // mean of the down-switching field beta
  double switch_sd_t = 0.2;           // standard deviation of both switching fields
  double weight_mean = 5;
  double weight_sd = 2.5;
  double weight_min = 0.01;  // weights below this are clipped up to it
  std::uint64_t seed = 1;
};

// A population of rectangular relays. Relay i is +1 (up) or -1 (down); applying a field B
// sets it to +1 when B >= alpha_i, to -1 when B <= beta_i, and leaves it unchanged in between.
// M/Ms = sum_i w_i s_i with sum_i w_i = 1, so all relays up gives M/Ms = 1.
//
// Construction (reproducible from params.seed on any platform, see PortableNormal): for each
// relay in turn alpha, beta and the weight are drawn from one std::mt19937_64 stream.
// - A relay needs alpha >= beta; when a draw has alpha < beta the two values are swapped, so
//   the relay keeps both drawn switching fields (alpha = max, beta = min). With the Fig. 1.5
//   parameters this affects about 0.7 % of the relays (P[N(0.7, 0.28) < 0]).
// - Weights are max(N(weight_mean, weight_sd), weight_min), then divided by their sum.
//
// Initial (demagnetized) state:
// - relays with alpha <= 0 start up and relays with beta >= 0 start down: the state that the
//   zero field forces (the same as apply_field(0) gives);
// - relays with beta < 0 < alpha are bistable at zero field. They are set in index order
//   (the relays are i.i.d., so this order is random) against the running magnetization S of
//   all relays set so far, forced ones included: down if S > 0, up if S < 0 and a seeded
//   fair coin if S == 0. The states carry no correlation with the switching fields, like a
//   random assignment, but the net moment cancels: |M/Ms| <= max_i w_i (~3e-5 for 1e5 relays)
//   whenever the bistable weight exceeds the forced imbalance, which it does for any
//   reasonable parameters. (A plain coin per relay would leave |M/Ms| ~ 1/sqrt(N).)
class PreisachModel {
 public:
  // Throws std::invalid_argument for relay_count < 1, non-finite values, switch_sd_t < 0,
  // weight_sd < 0 or weight_min <= 0.
  explicit PreisachModel(const PreisachParameters& params);

  // Applies the field B (tesla) to every relay and returns the new M/Ms.
  double apply_field(double b_tesla);

  // Current M/Ms.
  double magnetization() const { return magnetization_; }

  std::size_t relay_count() const { return weights_.size(); }
  const std::vector<double>& up_switching_fields_t() const { return alpha_; }
  const std::vector<double>& down_switching_fields_t() const { return beta_; }
  const std::vector<double>& weights() const { return weights_; }     // normalized, sum 1
  const std::vector<signed char>& states() const { return states_; }  // +1 up, -1 down

 private:
  double sum_magnetization() const;

  std::vector<double> alpha_;
  std::vector<double> beta_;
  std::vector<double> weights_;
  std::vector<signed char> states_;
  double magnetization_ = 0.0;
};

// M/Ms of a fresh PreisachModel(params) along the major-loop sweep
// 0 -> +b_max -> -b_max -> +b_max (see major_loop_sweep); the first point (B = 0, branch 0)
// is the demagnetized initial state. Fig. 1.5 corresponds to the default parameters.
MagnetizationCurve preisach_loop(const PreisachParameters& params, double b_max, double b_step);

}  // namespace mresim::magnetism
