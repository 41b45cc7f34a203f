#pragma once

// Central-difference helpers shared by the tests of src/mresim/mess (the term contract test,
// the term and system tests). The truncation error of (f(x + h) - f(x - h)) / (2h) is
// h^2 f''' / 6 and its rounding error about eps |f| / h; callers choose h and state their
// tolerance from these two.

#include <Eigen/Core>
#include <functional>
#include <vector>

namespace mresim::mess::testing {

// d f / d x_k by central differences for each listed flat coordinate k of x.
inline std::vector<double> central_differences(
    const std::function<double(const Eigen::Matrix3Xd&)>& f, const Eigen::Matrix3Xd& x,
    const std::vector<Eigen::Index>& coordinates, double step) {
  std::vector<double> out;
  out.reserve(coordinates.size());
  for (const Eigen::Index k : coordinates) {
    Eigen::Matrix3Xd p = x;
    Eigen::Matrix3Xd m = x;
    p.data()[k] += step;
    m.data()[k] -= step;
    out.push_back((f(p) - f(m)) / (2.0 * step));
  }
  return out;
}

// The full central-difference gradient of f (same shape as x).
inline Eigen::Matrix3Xd central_difference_gradient(
    const std::function<double(const Eigen::Matrix3Xd&)>& f, const Eigen::Matrix3Xd& x,
    double step) {
  Eigen::Matrix3Xd g(3, x.cols());
  for (Eigen::Index k = 0; k < x.size(); ++k) {
    Eigen::Matrix3Xd p = x;
    Eigen::Matrix3Xd m = x;
    p.data()[k] += step;
    m.data()[k] -= step;
    g.data()[k] = (f(p) - f(m)) / (2.0 * step);
  }
  return g;
}

// The derivative of a vector-valued g along a direction: (g(h) - g(-h)) / (2h), where g(t) is
// evaluated at the point moved by t times the direction (the caller's closure does the move).
template <typename Value>
Value directional_difference(const std::function<Value(double)>& g, double step) {
  return (g(step) - g(-step)) / (2.0 * step);
}

}  // namespace mresim::mess::testing
