#pragma once

// Newton-Krylov relaxation of the 3D system (MinimiserMethod::newton, minimiser.hpp): a line-
// search Newton method whose steps are solved by conjugate gradients on the exact Hessian,
// preconditioned by algebraic multigrid (amg_preconditioner.hpp). Truncated Newton (Nocedal &
// Wright, Numerical Optimization, Alg. 7.1): CG stops at the relative residual
// eta = min(forcing_max, sqrt(|g|_inf)) (superlinear convergence). The step cap (the largest
// coordinate change, in l_e) bounds CG's path as a trust region does (Steihaug-Toint, ibid.
// Alg. 7.2, in the max norm): at a direction of non-positive curvature, or where the path
// leaves the box, the step goes on along that direction to the box's boundary. The line
// search then judges the step, and the cap grows after boundary steps accepted whole.
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
// the rigid groups' translations, corrected by the positive part of the centre term (the stiff
// WCA contact) with the Woodbury identity. The multigrid is built once per run (NewtonCache)
// and rebuilt where CG slows down (note_convergence); the correction once per Newton step
// (3 N_p V-cycles).
//
// The Hessian is always the conservative one (centres = mean of all particle nodes). With the
// seed's CentreRule::centre_voxel, whose forces are not exactly a gradient, minimise() runs
// the conservative neighbour first and then Newton iterations on the seed's own forces with
// that Hessian as their Jacobian (the two differ by the particles' internal deformation) and
// the slope-only line search.

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "mresim/mess/solvers/amg_preconditioner.hpp"
#include "mresim/mess/solvers/hessian_assembly.hpp"
#include "mresim/mess/solvers/line_search.hpp"
#include "mresim/mess/solvers/relaxation_common.hpp"

namespace mresim::mess::detail {

using ConvergenceTest = std::function<bool(const Eigen::VectorXd&, double)>;

// Wall time of the parts of the solver (s).
struct NewtonTimings {
  double multigrid = 0.0;
  double products = 0.0;
  double centre_hessian = 0.0;
};

}  // namespace mresim::mess::detail

namespace mresim::mess {

// The multigrid of one set of constraints, with what it was built for.
struct NewtonPreconditioner {
  std::vector<std::uint8_t> own_dofs;  // DofMap::own_dof_mask() it was built for
  std::unique_ptr<ElasticMatrix> matrix;
  std::unique_ptr<AmgPreconditioner> amg;
  Eigen::VectorXd group_diagonal;  // H's diagonal on the rigid groups' translations
  // How fast CG converged with it: the most iterations per decade of residual reduction in
  // the first three solves after it was built. A later solve more than
  // NewtonOptions::multigrid_rebuild_slowdown times as slow (plus 2) marks it stale, and it is
  // rebuilt at the current positions before the next Newton step.
  double fresh_iterations_per_decade = 0.0;
  int reference_solves = 0;
  bool stale = false;
};

// Kept by a caller between minimise() calls (MinimiserOptions::newton_cache) so that the
// multigrid, whose setup costs about as much as 20-40 CG iterations, is built once per run
// rather than once per field or strain step: the elastic Hessian changes little between steps,
// and a preconditioner need only be close. Rebuilt when the constraints change, and whenever
// CG's convergence shows that the configuration has moved too far from the one it was built
// at (a pair snapping into contact: the gap between the particles is squeezed, springs turn).
struct NewtonCache {
  std::unique_ptr<NewtonPreconditioner> current;
  int setups = 0;
};

}  // namespace mresim::mess

namespace mresim::mess::detail {

// A Newton step in the scaled free variables, and whether CG stopped it on the box of the step
// cap (a direction of non-positive curvature, or the path leaving the box).
struct NewtonDirection {
  Eigen::VectorXd step;
  bool on_boundary = false;
};

class NewtonSolver {
 public:
  // `cache`: where the multigrid is kept (null: built for this solver alone).
  NewtonSolver(MessSystem& system, const DofMap& map, double force_scale,
               const NewtonOptions& options, std::shared_ptr<NewtonCache> cache = nullptr);

  // Newton steps from u until `converged`, the budget (Newton steps) or a failure.
  InnerResult run(Objective& f, Eigen::VectorXd& u, int budget, const MinimiserOptions& options,
                  bool use_energy, const ConvergenceTest& converged);
  std::int64_t krylov_iterations() const { return krylov_iterations_; }
  int newton_steps() const { return newton_steps_; }
  double preconditioner_seconds() const { return setup_seconds_; }
  const NewtonTimings& timings() const { return timings_; }

  // H v in the scaled free variables (see the header), at the system's current state; the
  // centre Hessian is the one of the last update_centre_hessian().
  Eigen::VectorXd hessian_product(const Eigen::VectorXd& v) const;
  // The preconditioner: approximately H^-1 r.
  Eigen::VectorXd precondition(const Eigen::VectorXd& r) const;
  void update_centre_hessian();

 private:
  void build_preconditioner();
  // Records how fast one CG solve converged: `iterations` to reduce the residual by the
  // factor `reduction` (< 1). Marks the multigrid stale if it converged much slower than the
  // first solve after the build (NewtonPreconditioner::fresh_iterations_per_decade).
  void note_convergence(int iterations, double reduction);
  // One V-cycle on the elastic part (plus Jacobi on the rigid groups).
  Eigen::VectorXd elastic_precondition(const Eigen::VectorXd& r) const;
  // The centre term's positive part in the preconditioner, by the Woodbury identity.
  void update_woodbury();
  // d ~ -H^-1 g by preconditioned CG to |r| <= eta |g| inside the box |d|_inf <= radius
  // (Steihaug-Toint): where CG's path leaves the box or meets non-positive curvature, the
  // step goes on along that CG direction to the box's boundary.
  NewtonDirection newton_direction(const Eigen::VectorXd& g, double eta, double radius);

  MessSystem& system_;
  const DofMap& map_;
  double force_scale_;
  NewtonOptions options_;
  Eigen::MatrixXd centre_hessian_;
  // Woodbury (update_woodbury): U (dofs x 3 N_p), K'_+ = the positive part of
  // K_c / (F0 l_e), W = B U and the capacitance I + K'_+ U^T W.
  Eigen::MatrixXd centre_directions_;
  Eigen::MatrixXd centre_stiffness_;
  Eigen::MatrixXd woodbury_w_;
  Eigen::PartialPivLU<Eigen::MatrixXd> woodbury_c_;
  std::shared_ptr<NewtonCache> cache_;
  NewtonPreconditioner* pc_ = nullptr;  // cache_->current
  std::int64_t krylov_iterations_ = 0;
  int newton_steps_ = 0;
  double setup_seconds_ = 0.0;
  mutable NewtonTimings timings_;
};

}  // namespace mresim::mess::detail
