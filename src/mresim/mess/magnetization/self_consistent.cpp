#include "mresim/mess/magnetization/self_consistent.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
#include <stdexcept>
#include <utility>

#include "mresim/mess/magnetization/particle_response.hpp"

namespace mresim::magnetism {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

// The problem in reduced units m = M/Ms, h = H/Ms (Section 4.2.3: "in practice the normalized
// magnetization M/Ms is used").
struct Problem {
  const DipoleCoupling& coupling;
  double chi;
  Eigen::Vector3d h_ext;
  const MagnetizationOptions& options;

  int n() const { return coupling.particle_count(); }

  // Local field h_ext + h_dip(m) at every particle (the bracket of eq. 4.58).
  Eigen::Matrix3Xd local_field(const Eigen::Matrix3Xd& m) const {
    Eigen::Matrix3Xd h = coupling.field(m);
    h.colwise() += h_ext;
    return h;
  }

  // The fixed-point map m -> FK(h_ext + h_dip(m)) (eq. 4.55 applied to eq. 4.58's field).
  Eigen::Matrix3Xd map(const Eigen::Matrix3Xd& m) const {
    Eigen::Matrix3Xd h = local_field(m);
    for (int i = 0; i < n(); ++i) {
      h.col(i) = particle_response(h.col(i), chi, options.demagnetization);
    }
    return h;
  }

  // max_q |r_q| / (atol + rtol |m_q|): <= 1 is the convergence test of Section 4.2.3.
  double scaled(const Eigen::Matrix3Xd& r, const Eigen::Matrix3Xd& m) const {
    double worst = 0.0;
    for (Eigen::Index k = 0; k < r.size(); ++k) {
      const double ratio =
          std::abs(r.data()[k]) / (options.atol + options.rtol * std::abs(m.data()[k]));
      if (!(ratio <= worst)) worst = ratio;  // NaN propagates as "worse"
    }
    if (std::isnan(worst)) return kInfinity;
    return worst;
  }

  // Magnetic energy over m in units of mu0 Ms^2 V: sum_i s(m_i) (eq. 4.76 [+ demag])
  // - sum_i m_i . h_ext (eq. 4.70) - (1/2) sum_i m_i . h_dip,i (eq. 4.71). Its gradient is
  // h(m_i) - h_local,i, zero exactly where the FK law holds.
  double energy(const Eigen::Matrix3Xd& m) const {
    const Eigen::Matrix3Xd h_dip = coupling.field(m);
    double e = 0.0;
    for (int i = 0; i < n(); ++i) {
      e += reduced_self_energy(m.col(i), chi, options.demagnetization) - m.col(i).dot(h_ext) -
           0.5 * m.col(i).dot(h_dip.col(i));
    }
    return e;
  }

  // blockdiag(dh/dm_i) - D: the Hessian of energy().
  Eigen::MatrixXd hessian(const Eigen::Matrix3Xd& m) const {
    Eigen::MatrixXd H = -coupling.dense();
    for (int i = 0; i < n(); ++i) {
      const Eigen::Index d = 3 * static_cast<Eigen::Index>(i);
      H.block<3, 3>(d, d) +=
          particle_response_inverse_jacobian(m.col(i), chi, options.demagnetization);
    }
    return H;
  }
};

// Lowest-residual state seen so far, over all methods.
struct Best {
  Eigen::Matrix3Xd m;
  Eigen::Matrix3Xd r;
  double scaled = kInfinity;
  MagnetizationMethod method = MagnetizationMethod::fixed_point;
  int iterations = 0;  // of `method` when it produced m
};

// Evaluates the residual at m, updates `best` and the attempt; true when converged. A state
// that meets the tolerance but is not `acceptable` (a saddle, for Newton) is not recorded.
bool evaluate(const Problem& p, const Eigen::Matrix3Xd& m, const Eigen::Matrix3Xd& g,
              MagnetizationAttempt& attempt, Best& best, double* scaled_out = nullptr,
              bool acceptable = true) {
  ++attempt.iterations;
  Eigen::Matrix3Xd r = g - m;
  const double s = p.scaled(r, m);
  if (scaled_out) *scaled_out = s;
  if (s <= 1.0 && !acceptable) return false;
  if (s < attempt.scaled_residual) attempt.scaled_residual = s;
  if (s < best.scaled) {
    best.m = m;
    best.r = std::move(r);
    best.scaled = s;
    best.method = attempt.method;
    best.iterations = attempt.iterations;
  }
  attempt.converged = s <= 1.0;
  return attempt.converged;
}

// Positive definite Hessian of the energy over m (a strict local minimum), by Cholesky.
bool is_stable(const Problem& p, const Eigen::Matrix3Xd& m) {
  for (Eigen::Index i = 0; i < m.cols(); ++i) {
    if (!(m.col(i).norm() < 1.0)) return false;
  }
  if (p.n() == 0) return true;
  const Eigen::LLT<Eigen::MatrixXd> llt(p.hessian(m));
  return llt.info() == Eigen::Success;
}

// Section 4.2.3's iteration m <- FK(h_ext + h_dip(m)), no relaxation.
void fixed_point(const Problem& p, Eigen::Matrix3Xd m, MagnetizationAttempt& attempt, Best& best) {
  std::vector<double> history;  // max |r| per iteration, for stall detection
  const int window = p.options.stall_window;
  for (int it = 0; it < p.options.max_fixed_point_iterations; ++it) {
    Eigen::Matrix3Xd g = p.map(m);
    if (evaluate(p, m, g, attempt, best)) return;
    const double size = (g - m).cwiseAbs().maxCoeff();
    if (!std::isfinite(size)) return;
    history.push_back(size);
    const std::size_t k = history.size();
    if (window > 0 && k > static_cast<std::size_t>(window) &&
        !(history[k - 1] < p.options.stall_factor * history[k - 1 - window])) {
      return;  // oscillating or crawling: hand over to the next method
    }
    m = std::move(g);
  }
}

// Anderson acceleration (type II, depth d) of the same map: with f = g(m) - m and the last d
// differences DF, DG of f and g, gamma = argmin |f - DF gamma|_2 and m <- g - DG gamma.
// Restarts from the best state when the residual grows a hundredfold.
void anderson(const Problem& p, Eigen::Matrix3Xd m, MagnetizationAttempt& attempt, Best& best) {
  const Eigen::Index size = 3 * static_cast<Eigen::Index>(p.n());
  std::deque<Eigen::VectorXd> df;
  std::deque<Eigen::VectorXd> dg;
  Eigen::VectorXd f_prev;
  Eigen::VectorXd g_prev;
  double smallest = kInfinity;  // of |f|_2 in this run
  for (int it = 0; it < p.options.max_anderson_iterations; ++it) {
    Eigen::Matrix3Xd g = p.map(m);
    if (evaluate(p, m, g, attempt, best)) return;
    const Eigen::VectorXd gv = Eigen::Map<const Eigen::VectorXd>(g.data(), size);
    const Eigen::VectorXd f = gv - Eigen::Map<const Eigen::VectorXd>(m.data(), size);
    const double norm = f.norm();
    if (!std::isfinite(norm)) return;
    if (norm > 100.0 * smallest) {
      // Diverging: forget the secant history and take a plain step from the best state.
      df.clear();
      dg.clear();
      f_prev.resize(0);
      m = best.m + best.r;
      continue;
    }
    smallest = std::min(smallest, norm);
    if (f_prev.size() == size) {
      df.emplace_back(f - f_prev);
      dg.emplace_back(gv - g_prev);
      if (static_cast<int>(df.size()) > p.options.anderson_depth) {
        df.pop_front();
        dg.pop_front();
      }
    }
    f_prev = f;
    g_prev = gv;
    Eigen::VectorXd next = gv;
    if (!df.empty()) {
      Eigen::MatrixXd F(size, static_cast<Eigen::Index>(df.size()));
      Eigen::MatrixXd G(size, static_cast<Eigen::Index>(dg.size()));
      for (std::size_t c = 0; c < df.size(); ++c) {
        F.col(static_cast<Eigen::Index>(c)) = df[c];
        G.col(static_cast<Eigen::Index>(c)) = dg[c];
      }
      const Eigen::VectorXd gamma = F.completeOrthogonalDecomposition().solve(f);
      if (gamma.allFinite()) next -= G * gamma;
    }
    m = Eigen::Map<const Eigen::Matrix3Xd>(next.data(), 3, p.n());
  }
}

// Largest alpha in (0, 1] with |m_i + alpha dm_i| <= fraction for every particle (stay inside
// the ball |m| < 1 where eq. 4.76 is finite).
double step_to_boundary(const Eigen::Matrix3Xd& m, const Eigen::Matrix3Xd& dm, double fraction) {
  double alpha = 1.0;
  for (Eigen::Index i = 0; i < m.cols(); ++i) {
    const double a = dm.col(i).squaredNorm();
    if (a == 0.0) continue;
    const double b = m.col(i).dot(dm.col(i));
    const double c = m.col(i).squaredNorm() - fraction * fraction;  // < 0 inside
    // Positive root of a t^2 + 2 b t + c = 0, written without cancellation.
    const double disc = std::sqrt(std::max(b * b - a * c, 0.0));
    const double t = b > 0.0 ? -c / (b + disc) : (disc - b) / a;
    alpha = std::min(alpha, t);
  }
  return alpha;
}

// Damped Newton minimisation of Problem::energy (stationary exactly at the FK law). A state
// is accepted only where the Hessian is positive definite: one that meets the tolerance on or
// near a saddle is left along the direction of most negative curvature.
void newton(const Problem& p, Eigen::Matrix3Xd m, MagnetizationAttempt& attempt, Best& best) {
  constexpr double kInside = 1.0 - 1e-9;
  for (Eigen::Index i = 0; i < m.cols(); ++i) {
    const double a = m.col(i).norm();
    if (!std::isfinite(a)) return;
    if (a >= kInside) m.col(i) *= kInside / a;
  }
  const Eigen::Index size = 3 * static_cast<Eigen::Index>(p.n());
  for (int it = 0; it < p.options.max_newton_iterations; ++it) {
    const Eigen::Matrix3Xd h = p.local_field(m);
    Eigen::Matrix3Xd g(3, p.n());
    Eigen::Matrix3Xd gradient(3, p.n());  // dE/dm_i = h(m_i) - h_local,i
    for (int i = 0; i < p.n(); ++i) {
      g.col(i) = particle_response(h.col(i), p.chi, p.options.demagnetization);
      gradient.col(i) =
          particle_response_inverse(m.col(i), p.chi, p.options.demagnetization) - h.col(i);
    }
    // Hessian: blockdiag of the inverse FK Jacobians (froehlich_kennelly_jacobian^-1 at the
    // field producing m_i) minus the dipole coupling D.
    const Eigen::MatrixXd H = p.hessian(m);
    Eigen::LLT<Eigen::MatrixXd> llt(H);
    const bool convex = llt.info() == Eigen::Success;
    double scaled = kInfinity;
    if (evaluate(p, m, g, attempt, best, &scaled, convex)) return;
    const Eigen::VectorXd grad = Eigen::Map<const Eigen::VectorXd>(gradient.data(), size);
    Eigen::VectorXd step;
    bool curvature_step = false;
    if (convex) {
      step = -llt.solve(grad);
    } else if (scaled <= 1.0) {
      // Stationary to the tolerance but not a minimum: follow the lowest eigenvector downhill.
      const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(H);
      step = eig.eigenvectors().col(0);
      if (grad.dot(step) > 0.0) step = -step;
      const Eigen::Map<const Eigen::Matrix3Xd> v(step.data(), 3, p.n());
      step *= 0.05 / v.colwise().norm().maxCoeff();  // move no particle by more than 0.05 Ms
      curvature_step = true;
    } else {
      // Indefinite far from stationarity: shift the Hessian until it is positive definite.
      const double beta = 1e-3 * H.diagonal().cwiseAbs().maxCoeff();
      double shift = beta;
      for (int tries = 0; tries < 200; ++tries) {
        llt.compute(H + shift * Eigen::MatrixXd::Identity(size, size));
        if (llt.info() == Eigen::Success) break;
        shift *= 2.0;
      }
      if (llt.info() != Eigen::Success) return;
      step = -llt.solve(grad);
    }
    const Eigen::Matrix3Xd dm = Eigen::Map<const Eigen::Matrix3Xd>(step.data(), 3, p.n());
    const double slope = grad.dot(step);  // <= 0: a descent direction
    if (!(slope < 0.0) && !curvature_step) return;
    // Backtracking (Armijo) on the energy, never leaving the ball; the slack lets a Newton
    // step through when the decrease is below rounding of the energy (near convergence),
    // while a curvature step must lower the energy by more than that.
    const double e0 = p.energy(m);
    const double slack = 1e-13 * (1.0 + std::abs(e0));
    double alpha = std::min(1.0, 0.99 * step_to_boundary(m, dm, kInside));
    bool accepted = false;
    while (!accepted && alpha > 1e-14) {
      const Eigen::Matrix3Xd trial = m + alpha * dm;
      const double e = p.energy(trial);
      const bool decrease =
          curvature_step ? e < e0 - slack : e <= e0 + 1e-4 * alpha * slope + slack;
      if (std::isfinite(e) && decrease) {
        m = trial;
        accepted = true;
      } else {
        alpha *= 0.5;
      }
    }
    if (!accepted) return;
  }
  // Budget spent: count the last iterate too.
  evaluate(p, m, p.map(m), attempt, best, nullptr, is_stable(p, m));
}

}  // namespace

std::string to_string(MagnetizationMethod method) {
  switch (method) {
    case MagnetizationMethod::fixed_point:
      return "fixed_point";
    case MagnetizationMethod::anderson:
      return "anderson";
    case MagnetizationMethod::newton:
      return "newton";
  }
  return "unknown";
}

std::string to_string(MagnetizationTolerance tolerance) {
  switch (tolerance) {
    case MagnetizationTolerance::tight:
      return "tight";
    case MagnetizationTolerance::original:
      return "original";
  }
  return "unknown";
}

void MagnetizationOptions::set_tolerance(MagnetizationTolerance tolerance) {
  switch (tolerance) {
    case MagnetizationTolerance::tight:
      atol = kTightAtol;
      rtol = kTightRtol;
      return;
    case MagnetizationTolerance::original:
      atol = kOriginalAtol;
      rtol = kOriginalRtol;
      return;
  }
}

MagnetizationOptions MagnetizationOptions::original() {
  MagnetizationOptions o;
  o.set_tolerance(MagnetizationTolerance::original);
  return o;
}

void MagnetizationOptions::validate() const {
  const auto fail = [](const std::string& what) {
    throw std::invalid_argument("MagnetizationOptions: " + what);
  };
  if (!(std::isfinite(atol) && atol >= 0.0)) fail("atol must be finite and >= 0");
  if (!(std::isfinite(rtol) && rtol >= 0.0)) fail("rtol must be finite and >= 0");
  if (!(atol > 0.0 || rtol > 0.0)) fail("atol and rtol cannot both be 0");
  if (methods.empty()) fail("methods must name at least one method");
  if (max_fixed_point_iterations < 1) fail("max_fixed_point_iterations must be >= 1");
  if (stall_window < 0) fail("stall_window must be >= 0");
  if (!(stall_factor > 0.0 && stall_factor <= 1.0)) fail("stall_factor must be in (0, 1]");
  if (max_anderson_iterations < 1) fail("max_anderson_iterations must be >= 1");
  if (anderson_depth < 1) fail("anderson_depth must be >= 1");
  if (max_newton_iterations < 1) fail("max_newton_iterations must be >= 1");
}

Eigen::Matrix3Xd magnetization_residual(const DipoleCoupling& coupling,
                                        const MagneticParticles& particles,
                                        const Eigen::Vector3d& applied_field,
                                        const Eigen::Matrix3Xd& M, bool demagnetization) {
  particles.validate();
  MagnetizationOptions options;
  options.demagnetization = demagnetization;
  const Problem p{coupling, particles.chi0, applied_field / particles.Ms, options};
  const Eigen::Matrix3Xd m = M / particles.Ms;
  return (p.map(m) - m) * particles.Ms;
}

MagnetizationResult solve_magnetization(const Eigen::Matrix3Xd& centres,
                                        const MagneticParticles& particles,
                                        const Eigen::Vector3d& applied_field,
                                        const Eigen::Matrix3Xd& initial_guess,
                                        const MagnetizationOptions& options) {
  particles.validate();
  return solve_magnetization(DipoleCoupling::open(centres, particles.volume()), particles,
                             applied_field, initial_guess, options);
}

MagnetizationResult solve_magnetization(const DipoleCoupling& coupling,
                                        const MagneticParticles& particles,
                                        const Eigen::Vector3d& applied_field,
                                        const Eigen::Matrix3Xd& initial_guess,
                                        const MagnetizationOptions& options) {
  particles.validate();
  options.validate();
  if (!applied_field.allFinite()) {
    throw std::invalid_argument("solve_magnetization: applied field is not finite");
  }
  const int n = coupling.particle_count();
  if (initial_guess.cols() != 0 && initial_guess.cols() != n) {
    throw std::invalid_argument("solve_magnetization: initial guess has " +
                                std::to_string(initial_guess.cols()) + " columns for " +
                                std::to_string(n) + " particles");
  }
  if (!initial_guess.allFinite()) {
    throw std::invalid_argument("solve_magnetization: initial guess is not finite");
  }
  const Problem p{coupling, particles.chi0, applied_field / particles.Ms, options};

  // History, or without one FK of the applied field alone (Section 4.2.3).
  Eigen::Matrix3Xd start(3, n);
  if (initial_guess.cols() == n) {
    start = initial_guess / particles.Ms;
  } else {
    for (int i = 0; i < n; ++i) {
      start.col(i) = particle_response(p.h_ext, p.chi, options.demagnetization);
    }
  }

  MagnetizationResult result;
  Best best;
  best.m = start;
  Eigen::Matrix3Xd from = start;  // where the next method starts
  for (const MagnetizationMethod method : options.methods) {
    MagnetizationAttempt attempt;
    attempt.method = method;
    Best local;  // this method's own best state
    local.m = from;
    switch (method) {
      case MagnetizationMethod::fixed_point:
        fixed_point(p, from, attempt, local);
        break;
      case MagnetizationMethod::anderson:
        anderson(p, from, attempt, local);
        // Anderson is a root finder: it also converges to unstable solutions (saddles of the
        // energy over M), which a relaxing system never occupies and which the fixed point
        // cannot reach. Accept its answer only at a local energy minimum.
        if (attempt.converged && !is_stable(p, local.m)) {
          attempt.converged = false;
          attempt.rejected_unstable = true;
        }
        break;
      case MagnetizationMethod::newton:
        newton(p, from, attempt, local);
        break;
    }
    result.total_iterations += attempt.iterations;
    result.attempts.push_back(attempt);
    if (attempt.converged) {
      best = local;
      break;
    }
    if (!attempt.rejected_unstable && local.scaled < best.scaled) best = local;
    // A failed Anderson run leaves the start unchanged: its iterates may sit near a saddle.
    if (method != MagnetizationMethod::anderson && local.scaled < kInfinity) from = local.m;
  }

  if (best.r.cols() != n) {
    // No method produced a usable state (e.g. Anderson alone, rejected): report the start.
    best.r = p.map(best.m) - best.m;
    best.scaled = p.scaled(best.r, best.m);
    best.method = options.methods.front();
    best.iterations = 0;
  }
  result.M = best.m * particles.Ms;
  result.method = best.method;
  result.iterations = best.iterations;
  result.scaled_residual = best.scaled;
  result.residual = n > 0 ? best.r.cwiseAbs().maxCoeff() : 0.0;
  result.converged = best.scaled <= 1.0;
  if (!std::isfinite(result.residual)) result.converged = false;

  if (options.check_stability) {
    bool inside = true;
    for (int i = 0; i < n; ++i) inside = inside && best.m.col(i).norm() < 1.0;
    if (!inside) {
      result.stability = Stability::unstable;
      result.min_hessian_eigenvalue = std::numeric_limits<double>::quiet_NaN();
    } else if (n == 0) {
      result.stability = Stability::stable;
      result.min_hessian_eigenvalue = kInfinity;
    } else {
      const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(p.hessian(best.m),
                                                               Eigen::EigenvaluesOnly);
      result.min_hessian_eigenvalue = eig.eigenvalues()(0);
      result.stability =
          result.min_hessian_eigenvalue > 0.0 ? Stability::stable : Stability::unstable;
    }
  } else {
    result.min_hessian_eigenvalue = std::numeric_limits<double>::quiet_NaN();
  }
  return result;
}

}  // namespace mresim::magnetism
