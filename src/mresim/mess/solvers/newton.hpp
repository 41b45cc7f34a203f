#pragma once

// Newton-Krylov relaxation of the 3D system (MinimiserMethod::newton, minimiser.hpp): a line-
// search Newton method whose steps are solved by conjugate gradients on the exact Hessian,
// preconditioned by algebraic multigrid (amg_preconditioner.hpp). Truncated Newton (Nocedal &
// Wright, Numerical Optimization, Alg. 7.1): CG stops at the relative residual
// eta = min(forcing_max, sqrt(|g|_inf)) (superlinear convergence), or at the first direction of
// non-positive curvature, and returns its iterate so far (the preconditioned gradient if that
// happens at the first step).
//
// The Hessian, in the free variables (scaled like the minimisers', relaxation_common.hpp):
//   H = P^T (H_elastic + S^T K_c S) P / F0
// P: the dofs' node directions (DofMap::expand), H_elastic: springs and volume exactly
// (MessSystem::elastic_hessian_product), S: the particle centres' dependence on the nodes
// (the mean over each particle's nodes), K_c: the reduced energy's Hessian in the centres,
// with M following the centres (MessSystem::reduced_centre_hessian, a 3 N_p matrix computed
// once per Newton step). So the Newton step sees how the magnetization changes with the
// configuration, which a fixed-M Hessian would not.
//
// Preconditioner: one GAMG V-cycle on the elastic Hessian (the coordinates that are dofs of
// their own; held coordinates and rigid-group nodes decoupled as identity), plus Jacobi for
// the rigid groups' translations. Built once per minimise() call at its starting positions
// and kept for all its Newton steps; the magnetic low-rank term is left to CG (3 N_p extra
// directions at most).
//
// Requires exact gradients: CentreRule::all_nodes (minimise() runs the seed's conservative
// neighbour first, and L-BFGS for its forces-only phase).

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <memory>

#include "mresim/mess/solvers/amg_preconditioner.hpp"
#include "mresim/mess/solvers/hessian_assembly.hpp"
#include "mresim/mess/solvers/line_search.hpp"
#include "mresim/mess/solvers/relaxation_common.hpp"

namespace mresim::mess::detail {

using ConvergenceTest = std::function<bool(const Eigen::VectorXd&, double)>;

class NewtonSolver {
 public:
  NewtonSolver(MessSystem& system, const DofMap& map, double force_scale,
               const NewtonOptions& options);

  // Newton steps from u until `converged`, the budget (Newton steps) or a failure.
  InnerResult run(Objective& f, Eigen::VectorXd& u, int budget, const MinimiserOptions& options,
                  bool use_energy, const ConvergenceTest& converged);

  std::int64_t krylov_iterations() const { return krylov_iterations_; }
  double preconditioner_seconds() const { return setup_seconds_; }

  // H v in the scaled free variables (see the header), at the system's current state; the
  // centre Hessian is the one of the last update_centre_hessian().
  Eigen::VectorXd hessian_product(const Eigen::VectorXd& v) const;
  // The preconditioner: approximately H^-1 r.
  Eigen::VectorXd precondition(const Eigen::VectorXd& r) const;
  void update_centre_hessian() { centre_hessian_ = system_.reduced_centre_hessian(); }

 private:
  void build_preconditioner();
  // d ~ -H^-1 g by preconditioned CG to |r| <= eta |g|, truncated at negative curvature (then
  // the iterate so far, or the preconditioned steepest descent at the first direction).
  Eigen::VectorXd newton_direction(const Eigen::VectorXd& g, double eta);

  MessSystem& system_;
  const DofMap& map_;
  double force_scale_;
  NewtonOptions options_;
  Eigen::MatrixXd centre_hessian_;
  std::unique_ptr<ElasticMatrix> matrix_;
  std::unique_ptr<AmgPreconditioner> amg_;
  Eigen::VectorXd group_diagonal_;  // H's diagonal on the rigid groups' translations
  std::int64_t krylov_iterations_ = 0;
  double setup_seconds_ = 0.0;
};

}  // namespace mresim::mess::detail
