#include "mresim/mess/protocols/load_step_start.hpp"

#include <fmt/format.h>

#include <cmath>
#include <stdexcept>
#include <utility>

namespace mresim::mess_protocol {
namespace {

void check_same_size(const char* function, const Eigen::Matrix3Xd& a, const Eigen::Matrix3Xd& b,
                     const char* a_name, const char* b_name) {
  if (a.cols() != b.cols()) {
    throw std::invalid_argument(fmt::format("{}: {} has {} columns, {} has {}", function, a_name,
                                            a.cols(), b_name, b.cols()));
  }
}

}  // namespace

Eigen::Matrix3Xd secant_start(const Eigen::Matrix3Xd& previous, const Eigen::Matrix3Xd& zero_load,
                              double c, double c_previous, double c_zero) {
  constexpr const char* kFn = "secant_start";
  check_same_size(kFn, previous, zero_load, "previous", "zero_load");
  if (!std::isfinite(c) || !std::isfinite(c_previous) || !std::isfinite(c_zero) ||
      c_previous == c_zero) {
    throw std::invalid_argument(
        fmt::format("{}: strain coordinates c = {}, c_previous = {}, c_zero = {}: all must be "
                    "finite and c_previous != c_zero",
                    kFn, c, c_previous, c_zero));
  }
  const double ratio = (c - c_previous) / (c_previous - c_zero);
  return previous + ratio * (previous - zero_load);
}

Eigen::Matrix3Xd field_secant_start(const Eigen::Matrix3Xd& previous,
                                    const Eigen::Matrix3Xd& earlier, const Eigen::Vector3d& b,
                                    const Eigen::Vector3d& b_previous,
                                    const Eigen::Vector3d& b_earlier) {
  constexpr const char* kFn = "field_secant_start";
  check_same_size(kFn, previous, earlier, "previous", "earlier");
  const Eigen::Vector3d last_change = b_previous - b_earlier;
  if (!b.allFinite() || !b_previous.allFinite() || !b_earlier.allFinite() ||
      last_change.squaredNorm() == 0.0) {
    throw std::invalid_argument(fmt::format(
        "{}: fields B = ({}, {}, {}), B_previous = ({}, {}, {}), B_earlier = ({}, {}, {}) T: "
        "all must be finite and B_previous != B_earlier",
        kFn, b.x(), b.y(), b.z(), b_previous.x(), b_previous.y(), b_previous.z(), b_earlier.x(),
        b_earlier.y(), b_earlier.z()));
  }
  const double ratio = (b - b_previous).dot(last_change) / last_change.squaredNorm();
  return previous + ratio * (previous - earlier);
}

Eigen::Matrix3Xd neighbour_field_start(const Eigen::Matrix3Xd& zero_load,
                                       const Eigen::Matrix3Xd& neighbour_loaded,
                                       const Eigen::Matrix3Xd& neighbour_zero_load) {
  constexpr const char* kFn = "neighbour_field_start";
  check_same_size(kFn, zero_load, neighbour_loaded, "zero_load", "neighbour_loaded");
  check_same_size(kFn, zero_load, neighbour_zero_load, "zero_load", "neighbour_zero_load");
  return zero_load + (neighbour_loaded - neighbour_zero_load);
}

int take_lowest(mess::MessSystem& system, std::vector<Eigen::Matrix3Xd>& candidates) {
  for (const Eigen::Matrix3Xd& candidate : candidates) {
    check_same_size("take_lowest", system.positions(), candidate, "the system's positions",
                    "a candidate");
  }
  const Eigen::Matrix3Xd magnetization = system.magnetizations();
  const bool history = system.has_magnetization_history();
  double lowest = system.evaluate(nullptr).potential;
  int best = -1;
  Eigen::Matrix3Xd best_magnetization;
  const int last = static_cast<int>(candidates.size()) - 1;
  for (int i = 0; i <= last; ++i) {
    if (history) system.set_magnetizations(magnetization);
    std::swap(system.mutable_positions(), candidates[i]);
    system.apply_constraints();
    const double potential = system.evaluate(nullptr).potential;
    // Not above the system's own potential; strictly below an earlier candidate's.
    const bool lower =
        std::isfinite(potential) && (best < 0 ? potential <= lowest : potential < lowest);
    if (lower) {
      best = i;
      lowest = potential;
      if (i == last) return best;  // the system holds it, with M solved there
      best_magnetization = system.magnetizations();
    }
    std::swap(system.mutable_positions(), candidates[i]);
  }
  if (best < 0) {
    if (history) system.set_magnetizations(magnetization);
    return -1;
  }
  std::swap(system.mutable_positions(), candidates[best]);
  system.set_magnetizations(best_magnetization);
  return best;
}

bool take_if_not_higher(mess::MessSystem& system, Eigen::Matrix3Xd& candidate) {
  std::vector<Eigen::Matrix3Xd> one;
  one.push_back(std::move(candidate));
  const int taken = take_lowest(system, one);
  candidate = std::move(one.front());
  return taken == 0;
}

}  // namespace mresim::mess_protocol
