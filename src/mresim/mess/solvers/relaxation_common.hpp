#pragma once

// Pieces shared by the relaxation methods (minimiser.cpp, leapfrog.cpp): the scaled objective
// over the free variables, the convergence force measure, and the characteristic mass.

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "mresim/mess/system/constraints.hpp"
#include "mresim/mess/system/system_energy.hpp"

namespace mresim::mess {
class DistributedEvaluator;  // distributed/distributed_evaluator.hpp
}  // namespace mresim::mess

namespace mresim::mess::detail {

// m_c = rho_polymer l_e^3, the mass of an interior polymer node (Section 4.2.6), recovered from
// the lattice's masses: a polymer node has rho_polymer l_e^3 (cells at the node)/8.
double characteristic_mass(const lattice::Lattice& lattice);

// Largest |component| over: free coordinates of nodes outside rigid groups, rigid-group net
// forces, and particle net forces (sum over the particle's nodes, held coordinates excluded).
class ForceMeasure {
 public:
  ForceMeasure(const MessSystem& system, const DofMap& map);
  double max_force(const Eigen::Matrix3Xd& gradient) const;  // N for a gradient in J/m

 private:
  const DofMap& map_;
  const std::vector<std::vector<std::int32_t>>& particles_;
  std::vector<std::uint8_t> fixed_;
};

// The potential as a function of the free variables u (units of l_e), scaled by E0 = F0 l_e
// (F0 = the force scale), so that the scaled gradient components are forces in units of F0.
// Every call moves the system to u and evaluates it (re-solving M per the system's rule).
class Objective {
 public:
  // With `distributed` not null every evaluation is split over its processes (each process
  // holding the same system and calling at the same time): the same gradient, energies to
  // rounding (distributed/distributed_evaluator.hpp).
  Objective(MessSystem& system, const DofMap& map, double force_scale,
            DistributedEvaluator* distributed = nullptr);

  double operator()(const Eigen::VectorXd& u, Eigen::VectorXd& gradient);
  // The same at u + alpha d, without forming that vector (the line searches' trial points).
  double along(const Eigen::VectorXd& u, double alpha, const Eigen::VectorXd& d,
               Eigen::VectorXd& gradient);

  // A constant load added to the potential until clear_load(): gradient += `load` (3 x N,
  // J/m, the layout of full_gradient()) and potential += load . (x - x(u_ref)). The
  // minimiser's correction passes for the seed's forces use it (minimiser.cpp).
  // full_gradient() includes the load.
  void set_load(const Eigen::Matrix3Xd& load, const Eigen::VectorXd& u_ref);
  void clear_load();

  double energy_scale() const { return e0_; }
  MessSystem& system() { return system_; }
  // The potential's rounding scale (sum of |terms|) of the last evaluation, scaled.
  double magnitude() const { return last_.magnitude / e0_; }
  const Evaluation& last_evaluation() const { return last_; }
  const Eigen::Matrix3Xd& full_gradient() const { return gradient_; }
  std::int64_t evaluations() const { return evaluations_; }

 private:
  MessSystem& system_;
  const DofMap& map_;
  double e0_;
  DistributedEvaluator* distributed_;
  Evaluation last_;
  Eigen::Matrix3Xd gradient_;
  std::int64_t evaluations_ = 0;
  // Evaluates the system where it stands (at dofs u) into `gradient`; returns the potential.
  template <class Dofs>
  double evaluate_here(const Dofs& u, Eigen::VectorXd& gradient);

  // The load is nonzero on a few nodes (the particles'), so it is kept there only: a full
  // copy of the load, of its reduced form and of u_ref would add 72 bytes per node to a
  // correction pass's peak memory.
  struct ReducedLoad {
    Eigen::Index dof;  // a free variable the load acts on
    double value;      // the load on it, scaled
    double origin;     // u_ref there
  };
  bool loaded_ = false;
  std::vector<std::int32_t> load_nodes_;   // the nodes with a nonzero load
  Eigen::Matrix3Xd load_columns_;          // their load (J/m)
  std::vector<ReducedLoad> load_reduced_;  // the nonzero load components on the free variables
};

}  // namespace mresim::mess::detail
