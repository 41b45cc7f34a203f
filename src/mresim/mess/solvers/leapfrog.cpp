#include "mresim/mess/solvers/leapfrog.hpp"

#include <cmath>
#include <numbers>
#include <stdexcept>

#include "mresim/mess/solvers/relaxation_common.hpp"

namespace mresim::mess {

LeapfrogScales LeapfrogScales::of(const lattice::Lattice& lat) {
  LeapfrogScales s;
  const lattice::SpringConstants& k = lat.polymer.springs;
  s.length = lat.element_length;
  s.mass = detail::characteristic_mass(lat);
  s.k_eff = lattice::effective_spring_constant(k);
  s.time = 2.0 * std::numbers::pi * std::sqrt(s.mass / s.k_eff);  // eq. 4.94
  s.beta = s.time * s.time / s.length;
  return s;
}

void LeapfrogOptions::validate() const {
  const auto fail = [](const std::string& what) {
    throw std::invalid_argument("LeapfrogOptions: " + what);
  };
  if (!(time_step > 0.0 && std::isfinite(time_step))) fail("time_step must be > 0");
  if (!(drag >= 0.0 && std::isfinite(drag))) fail("drag must be >= 0");
  if (steps_per_round < 1) fail("steps_per_round must be >= 1");
  if (max_rounds < 1) fail("max_rounds must be >= 1");
  if (min_rounds < 1) fail("min_rounds must be >= 1");
  if (consecutive_rounds < 1) fail("consecutive_rounds must be >= 1");
  if (difference_interval < 1) fail("difference_interval must be >= 1");
  if (!std::isfinite(tolerance)) fail("tolerance must be finite");
}

std::string to_string(LeapfrogStatus status) {
  switch (status) {
    case LeapfrogStatus::converged:
      return "converged";
    case LeapfrogStatus::max_rounds:
      return "max_rounds";
    case LeapfrogStatus::not_finite:
      return "not_finite";
  }
  return "unknown";
}

double seed_convergence_tolerance(const lattice::Lattice& lat, double time_step) {
  // Scaled initial coordinates are the integers (ix, iy, iz): average the float32 spacing above
  // each value over all coordinates of all nodes.
  double sum = 0.0;
  const auto ulp = [](int value) {
    const auto f = static_cast<float>(value);
    return static_cast<double>(std::nextafter(f, INFINITY) - f);
  };
  const std::int64_t n = lat.node_count();
  for (int a = 0; a < 3; ++a) {
    const int count = lat.shape.nodes[a];
    const double others = static_cast<double>(n) / count;  // nodes sharing each value
    for (int i = 0; i < count; ++i) sum += others * ulp(i);
  }
  return sum / (3.0 * static_cast<double>(n)) / time_step;
}

namespace {

// Masks and the acceleration assembly of one system.
class Accelerations {
 public:
  Accelerations(MessSystem& system, const LeapfrogOptions& options, const LeapfrogScales& scales)
      : system_(system), options_(options) {
    const lattice::Lattice& lat = system.lattice();
    const std::int64_t n = lat.node_count();
    beta_ = scales.beta * lat.masses.cwiseInverse();  // beta_i = t_c^2 / (l_e m_i)
    const BoundaryConstraints& c = system.constraints();
    main_mask_.assign(static_cast<std::size_t>(3 * n), 0);
    boundary_mask_.assign(static_cast<std::size_t>(3 * n), 0);
    const Eigen::Matrix3Xd& f = system.applied_forces();
    for (std::int64_t i = 0; i < n; ++i) {
      const bool particle =
          !lat.particle_of_node.empty() && lat.particle_of_node[static_cast<std::size_t>(i)] >= 0;
      const bool loaded = f.cols() > 0 && f.col(i).squaredNorm() > 0.0;
      for (int a = 0; a < 3; ++a) {
        const auto k = static_cast<std::size_t>(3 * i + a);
        if (c.is_fixed(i, a)) continue;
        if (!particle) main_mask_[k] = 1;
        if (loaded) boundary_mask_[k] = 1;
      }
    }
    for (const RigidGroup& g : c.rigid_groups) {
      for (const std::int32_t i : g.nodes) {
        for (int a = 0; a < 3; ++a) boundary_mask_[3 * static_cast<std::size_t>(i) + a] = 1;
      }
    }
    for (const std::uint8_t b : main_mask_) main_count_ += b;
    for (const std::uint8_t b : boundary_mask_) boundary_count_ += b;
  }

  // a(x, v) in l_e/t_c^2 for the system's current positions; false if not finite.
  bool compute(const Eigen::Matrix3Xd& v, Eigen::Matrix3Xd& a) {
    last_ = system_.evaluate(&gradient_);
    a = -(gradient_.array().rowwise() * beta_.transpose().array()).matrix();
    a -= options_.drag * v;
    const BoundaryConstraints& c = system_.constraints();
    if (!c.fixed.empty()) {
      for (Eigen::Index k = 0; k < a.size(); ++k) {
        if (c.fixed[static_cast<std::size_t>(k)] != 0) a.data()[k] = 0.0;
      }
    }
    const Eigen::VectorXd& m = system_.lattice().masses;
    for (const RigidGroup& g : c.rigid_groups) {
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      double weight = 0.0;
      for (const std::int32_t i : g.nodes) {
        const double w = options_.rigid_group_rule == RigidGroupRule::total_force ? m[i] : 1.0;
        sum += w * a.col(i);
        weight += w;
      }
      const Eigen::Vector3d mean = sum / weight;
      for (const std::int32_t i : g.nodes) a.col(i) = mean;
    }
    return a.allFinite();
  }

  double main_mean(const Eigen::Matrix3Xd& q) const {
    return masked_mean(q, main_mask_, main_count_);
  }
  double boundary_mean(const Eigen::Matrix3Xd& q) const {
    return masked_mean(q, boundary_mask_, boundary_count_);
  }
  bool has_boundary() const { return boundary_count_ > 0; }
  const Evaluation& last() const { return last_; }

 private:
  static double masked_mean(const Eigen::Matrix3Xd& q, const std::vector<std::uint8_t>& mask,
                            std::int64_t count) {
    if (count == 0) return 0.0;
    double sum = 0.0;
    for (Eigen::Index k = 0; k < q.size(); ++k) {
      if (mask[static_cast<std::size_t>(k)] != 0) sum += std::abs(q.data()[k]);
    }
    return sum / static_cast<double>(count);
  }

  MessSystem& system_;
  const LeapfrogOptions& options_;
  Eigen::VectorXd beta_;
  std::vector<std::uint8_t> main_mask_, boundary_mask_;
  std::int64_t main_count_ = 0, boundary_count_ = 0;
  Eigen::Matrix3Xd gradient_;
  Evaluation last_;
};

}  // namespace

LeapfrogResult relax_leapfrog(MessSystem& system, const LeapfrogOptions& options) {
  options.validate();
  LeapfrogResult res;
  res.scales = LeapfrogScales::of(system.lattice());
  const double dt = options.time_step;
  const double l_e = res.scales.length;
  res.tolerance = options.tolerance > 0.0 ? options.tolerance
                                          : seed_convergence_tolerance(system.lattice(), dt);
  const double tol = res.tolerance;
  const MagnetizationStats stats0 = system.magnetization_stats();

  system.apply_constraints();
  Accelerations acc(system, options, res.scales);
  Eigen::Matrix3Xd& x = system.mutable_positions();
  Eigen::Matrix3Xd v = Eigen::Matrix3Xd::Zero(3, x.cols());
  Eigen::Matrix3Xd a;
  bool finite = acc.compute(v, a);
  v += 0.5 * dt * a;  // Euler kick-start to v(dt/2)

  Eigen::Matrix3Xd sample = x;
  std::vector<double> difference_norms;
  int consecutive = 0;
  int max_rounds = options.max_rounds;
  const std::size_t particles = system.particle_count();
  while (finite) {
    for (int step = 0; step < options.steps_per_round; ++step) {
      x += (dt * l_e) * v;  // eq. 4.88
      if (!acc.compute(v, a)) {
        finite = false;
        break;
      }
      v += dt * a;  // eq. 4.89
      ++res.steps;
      if (res.steps % options.difference_interval == 0) {
        difference_norms.push_back((x - sample).norm() / l_e);
        sample = x;
        if (options.observer) options.observer({res.steps, acc.main_mean(a)});
      }
    }
    ++res.rounds;
    if (!finite) {
      res.status = LeapfrogStatus::not_finite;
      break;
    }
    LeapfrogRound r;
    r.mean_abs_acceleration = acc.main_mean(a);
    r.mean_abs_velocity = acc.main_mean(v);
    r.criterion_met = r.mean_abs_acceleration < tol && r.mean_abs_velocity < tol;
    if (acc.has_boundary()) {
      r.boundary_mean_abs_acceleration = acc.boundary_mean(a);
      r.boundary_mean_abs_velocity = acc.boundary_mean(v);
      r.criterion_met = r.criterion_met && r.boundary_mean_abs_acceleration < tol &&
                        r.boundary_mean_abs_velocity < tol;
    }
    r.difference_norm = difference_norms.empty() ? 0.0 : difference_norms.back();
    res.history.push_back(r);
    consecutive = r.criterion_met ? consecutive + 1 : 0;
    const std::size_t nd = difference_norms.size();
    const bool settling = nd < 2 || difference_norms[nd - 1] - difference_norms[nd - 2] <= 0.0;
    if ((r.criterion_met && options.first_round_may_end) ||
        (consecutive >= options.consecutive_rounds && res.rounds >= options.min_rounds &&
         settling)) {
      res.status = LeapfrogStatus::converged;
      break;
    }
    if (res.rounds >= max_rounds) {
      bool moving = false;
      if (options.extend_for_moving_particles && particles >= 1 && particles <= 7 &&
          max_rounds < 2 * options.max_rounds) {
        Eigen::Vector3d mean = Eigen::Vector3d::Zero();
        const auto& nodes = system.lattice().particle_nodes[0];
        for (const std::int32_t n : nodes) mean += v.col(n);
        mean /= static_cast<double>(nodes.size());
        moving = mean.cwiseAbs().maxCoeff() > tol;
      }
      if (!moving) {
        res.status = LeapfrogStatus::max_rounds;
        break;
      }
      ++max_rounds;
    }
  }
  res.converged = res.status == LeapfrogStatus::converged;
  res.velocities = v;
  res.final = acc.last();
  const MagnetizationStats& stats = system.magnetization_stats();
  res.magnetization_solves = stats.solves - stats0.solves;
  res.unconverged_magnetization_solves = stats.unconverged - stats0.unconverged;
  return res;
}

}  // namespace mresim::mess
