#include "mresim/mess/solvers/line_search.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "mresim/mess/solvers/vector_algebra.hpp"

namespace mresim::mess::detail {

bool StallGuard::stalled(const Eigen::VectorXd& g, double change, const Objective& f,
                         bool use_energy) {
  const double gmax = parallel_max_abs(g);
  // An energy decrease counts as progress down to eps times the potential's rounding scale:
  // the bound on the rounding of a sum, which its typical rounding stays well below. With
  // 64 eps (the line search's slack), a full-size pair in contact (Fig. 4.11 at 40 mT,
  // magnitude 4.4e4 E0) was declared stalled at 6e-5 F0 while its energy still fell by
  // 1e-10 E0 per iteration, every time, and FIRE had to finish the step; with eps it
  // converges (docs/performance.md, "Routes measured for L-BFGS").
  const double noise = std::numeric_limits<double>::epsilon() * f.magnitude();
  if (gmax < best_gradient_ || (use_energy && change < -noise)) {
    best_gradient_ = std::min(best_gradient_, gmax);
    count_ = 0;
    return false;
  }
  return ++count_ >= limit_;
}

// At full size every gradient is 24 bytes per node, so the search keeps only the ones it may
// return: not the start's (alpha = 0 is never accepted) nor the upper ends' of the zoom.
bool wolfe_line_search(Objective& f, const Eigen::VectorXd& u, const Eigen::VectorXd& d,
                       const LinePoint& from, double alpha_init, double alpha_max, bool use_energy,
                       LinePoint& out) {
  const LinePoint start{0.0, from.phi, from.dphi, {}};
  constexpr double c1 = 1e-4;
  constexpr double c2 = 0.9;
  constexpr int kMaxTrials = 40;
  const double slack = 64.0 * std::numeric_limits<double>::epsilon() * f.magnitude();
  double last_alpha = 0.0;  // where the system was evaluated last
  const auto eval = [&](double alpha) {
    last_alpha = alpha;
    LinePoint p;
    p.alpha = alpha;
    p.phi = f.along(u, alpha, d, p.g);
    p.dphi = parallel_dot(p.g, d);
    return p;
  };
  const auto armijo_fails = [&](const LinePoint& p) {
    return !std::isfinite(p.phi) || !std::isfinite(p.dphi) ||
           (use_energy && p.phi > start.phi + c1 * p.alpha * start.dphi + slack);
  };
  const auto higher = [&](const LinePoint& p, const LinePoint& than) {
    return use_energy && p.phi > than.phi + slack;
  };
  const auto curvature_holds = [&](const LinePoint& p) {
    return std::abs(p.dphi) <= -c2 * start.dphi;
  };
  int trials = 0;
  // zoom(lo, hi): lo satisfies sufficient decrease, the minimiser lies between lo and hi.
  const auto zoom = [&](LinePoint lo, LinePoint hi) {
    hi.g.resize(0);
    while (trials < kMaxTrials) {
      const double a = std::min(lo.alpha, hi.alpha);
      const double b = std::max(lo.alpha, hi.alpha);
      double alpha;
      if (std::isfinite(hi.phi) && lo.dphi * hi.dphi < 0.0) {
        alpha = lo.alpha - lo.dphi * (hi.alpha - lo.alpha) / (hi.dphi - lo.dphi);  // secant on phi'
      } else {
        alpha = 0.5 * (a + b);
      }
      alpha = std::clamp(alpha, a + 0.1 * (b - a), b - 0.1 * (b - a));
      LinePoint p = eval(alpha);
      ++trials;
      if (armijo_fails(p) || higher(p, lo)) {
        hi = std::move(p);
        hi.g.resize(0);
      } else {
        if (curvature_holds(p)) {
          out = std::move(p);
          return true;
        }
        if (p.dphi * (hi.alpha - lo.alpha) >= 0.0) {
          hi = std::move(lo);
          hi.g.resize(0);
        }
        lo = std::move(p);
      }
      if (std::abs(hi.alpha - lo.alpha) < 1e-12 * std::max(lo.alpha, hi.alpha)) break;
    }
    // Accept the best point with sufficient decrease if it made progress: lower energy beyond
    // the noise, or a smaller slope.
    if (lo.alpha > 0.0 && ((use_energy && lo.phi < start.phi - slack) ||
                           std::abs(lo.dphi) < 0.5 * std::abs(start.dphi))) {
      out = std::move(lo);
      return true;
    }
    return false;
  };

  LinePoint prev = start;
  double alpha = std::min(alpha_init, alpha_max);
  bool ok = false;
  while (trials < kMaxTrials) {
    LinePoint p = eval(alpha);
    ++trials;
    if (armijo_fails(p) || (prev.alpha > 0.0 && higher(p, prev))) {
      ok = zoom(std::move(prev), std::move(p));
      break;
    }
    if (curvature_holds(p)) {
      out = std::move(p);
      ok = true;
      break;
    }
    if (p.dphi >= 0.0) {
      ok = zoom(std::move(p), std::move(prev));
      break;
    }
    if (alpha >= alpha_max) {  // cannot go further: accept the longest allowed step
      out = std::move(p);
      ok = true;
      break;
    }
    prev = std::move(p);
    alpha = std::min(2.0 * alpha, alpha_max);
  }
  if (ok && last_alpha != out.alpha) {
    Eigen::VectorXd g;
    (void)f.along(u, out.alpha, d, g);  // leave the system at the accepted point
  }
  return ok;
}

}  // namespace mresim::mess::detail
