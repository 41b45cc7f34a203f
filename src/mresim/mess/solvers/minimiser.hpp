#pragma once

// Fast relaxation of the 3D system to a local minimum of its potential (system_energy.hpp):
// L-BFGS (default) or FIRE, on scaled variables (lengths in units of l_e, energies in units of
// E0 = k_eff l_e^2, so scaled gradients are forces in units of F0 = k_eff l_e), with the particle
// magnetizations re-solved between outer iterations. The seed's damped leapfrog
// (leapfrog.hpp) reaches the same states with far more force evaluations.
//
//  - lbfgs: limited-memory BFGS (Nocedal & Wright, Numerical Optimization, Alg. 7.4-7.5) with a
//    strong-Wolfe line search (Alg. 3.5-3.6), preconditioned by RigidParticlePreconditioner
//    (initial inverse Hessian gamma P: Jacobi scaling plus the particles' rigid motions at the
//    polymer's stiffness; 25-30x fewer iterations with particles, preconditioner.hpp). The
//    line search tolerates rounding noise in the energy: sufficient decrease is tested with a
//    slack of a few ulps of the energy's terms and the zoom interpolates the directional
//    derivative, so it keeps making progress where energy differences are below the energy's
//    rounding error. Hand-written on Eigen: Debian's LBFGS++ (liblbfgspp-dev) would add a
//    build dependency and lacks the preconditioned initial Hessian and the noise-tolerant search.
//  - newton: Newton-Krylov with an algebraic-multigrid preconditioner (newton.hpp): outer
//    iterations independent of the lattice size, cost per relaxation growing like N.
//  - fire: the Fast Inertial Relaxation Engine (Bitzek et al., PRL 97, 170201 (2006)) with the
//    semi-implicit Euler step and the uphill correction of FIRE 2.0 (Guenole et al., Comput.
//    Mater. Sci. 175, 109584 (2020)), nodal masses as in the dynamics, dt_max from the highest
//    lattice frequency (power iteration). Needs only forces, so it also relaxes the seed's
//    non-conservative force field (CentreRule::centre_voxel) exactly. Not preconditioned: with
//    particles it needs 30-50x more iterations than lbfgs.
//
// Seed profile (CentreRule::centre_voxel): its spread particle forces are not exactly the
// potential's gradient (they differ by the particles' internal deformation), which L-BFGS's
// line search cannot live with. L-BFGS therefore relaxes the conservative neighbour (centre =
// mean of all nodes) first; then the seed's own forces are evaluated and, if above the
// tolerance (forces_only_phase), L-BFGS continues in correction passes: the neighbour's
// potential plus the seed's force difference frozen as a constant load, re-frozen after each
// pass; the conservative phase and each pass only to a fraction (correction_forcing) of what
// the next pass corrects, the last one to the tolerance. Should a pass fail, L-BFGS goes on with a
// slope-only line search on the seed's forces (no energy tests), and FIRE finishes should that fail
// too. The result always meets the tolerance on the profile's own forces.
//
// Fallbacks, reported in MinimiserResult: when the L-BFGS line search fails or stalls, with
// every_evaluation coupling the minimiser switches to alternating; if it fails again, FIRE
// finishes from where L-BFGS stopped.
//
// Magnetization (MagnetizationCoupling):
//  - every_evaluation (default): M is re-solved (with history) at every evaluation, i.e. the
//    reduced energy E(x, M(x)) is minimised; its gradient is the fixed-M gradient by the
//    envelope theorem. M solved to a finite tolerance makes E(x, M(x)) slightly rough (the
//    solver returns its history unchanged while that is within tolerance); should the line
//    search stall on it, the minimiser switches to alternating for the rest of the call.
//  - alternating: the inner minimisation runs at fixed M; between outer iterations M is
//    re-solved and the forces re-checked (block-coordinate descent on E(x, M)). About 2-3 times
//    more iterations when M changes a lot during the relaxation.
//
// Convergence (checked with the current M after it has been re-solved): the largest force on
// any free coordinate, the net force on any rigid group and the net force on any particle are
// all <= force_tolerance x force_scale, AND the potential changed by at most
// energy_tolerance x max(sum of |terms|, E0) over the last iteration (E0 = force_scale l_e; the
// floor keeps tiny energies, dominated by their own rounding, from blocking convergence).

#include <cstdint>
#include <memory>
#include <string>

#include "mresim/mess/solvers/amg_preconditioner.hpp"
#include "mresim/mess/solvers/contact_gap.hpp"
#include "mresim/mess/solvers/node_scaling.hpp"
#include "mresim/mess/solvers/relaxation_observer.hpp"
#include "mresim/mess/system/system_energy.hpp"

namespace mresim::mess {

enum class MinimiserMethod { lbfgs, fire, newton };
// L-BFGS's initial inverse Hessian H0 = gamma P:
//  automatic (the default; run files' method = "minimiser"): multilevel for lattices of at
//    least kMultilevelMinimumNodes nodes, else rigid_particles;
//  multilevel: RigidParticlePreconditioner with its multilevel correction (preconditioner.hpp,
//    multilevel_correction.hpp): L-BFGS's iterations nearly independent of the lattice's size,
//    each about 20 % dearer; it pays from a few 10,000 nodes on (docs/performance.md);
//  rigid_particles: RigidParticlePreconditioner alone (run files' method = "lbfgs");
//  multigrid: Newton's preconditioner (newton.hpp: one GAMG V-cycle on the elastic Hessian
//    with the contact term's Woodbury correction). Measured in docs/performance.md: L-BFGS's
//    iterations stay at 58-93 from 5k to 49k nodes (not 218-2,236), but a V-cycle costs
//    about 12 evaluations at 16k nodes and 46 at 285k (serial PETSc), so it beat the
//    default only at 49k nodes (1.23x) and Newton nowhere. Kept to measure the route
//    (mess_scaling_bench); not offered in run files.
enum class LbfgsPreconditioner { automatic, multilevel, rigid_particles, multigrid };
// Where `automatic` turns to the multilevel preconditioner. mess_scaling_bench, one field step
// of the same pair at five lattice sizes: multilevel/rigid_particles wall time 1.4x at 14,400
// nodes, 1.06x at 26,496 and 0.75x at 48,600 (docs/performance.md).
inline constexpr std::int64_t kMultilevelMinimumNodes = 40000;
// How L-BFGS stores its pairs (lbfgs_memory.hpp):
//  automatic (the default): single precision where the preconditioner is the multilevel one
//    (so run files' method = "minimiser" from kMultilevelMinimumNodes nodes on), else double;
//  double_precision, single_precision.
// In single precision the ten pairs take 240 instead of 480 bytes per node, the largest part
// of a relaxation's memory, and the recursion sweeps half the bytes; the product is the L-BFGS
// operator of the rounded pairs (still symmetric positive definite). Measured in
// docs/performance.md ("The L-BFGS pairs in single precision").
enum class LbfgsHistoryPrecision { automatic, double_precision, single_precision };
enum class MagnetizationCoupling { alternating, every_evaluation };
// stalled: 50 L-BFGS iterations without a new smallest force or an energy decrease beyond
// rounding (the tolerance is below what the configuration's rounding allows).
enum class MinimiserStatus { converged, max_iterations, line_search_failed, stalled, not_finite };

std::string to_string(MinimiserMethod method);
std::string to_string(MinimiserStatus status);

// Bitzek et al. (2006) parameters.
struct FireParameters {
  int n_min = 5;
  double f_inc = 1.1;
  double f_dec = 0.5;
  double alpha_start = 0.1;
  double f_alpha = 0.99;
  // Time step limit in units of 1/omega_max (omega_max estimated by power iteration on the
  // mass-weighted Hessian); semi-implicit Euler is stable below 2.
  double dt_max_factor = 1.0;
  double dt_start_factor = 0.25;
  int power_iterations = 30;
};

// Newton-Krylov (newton.hpp).
struct NewtonOptions {
  int max_krylov_iterations = 1000;  // CG iterations per Newton step
  // CG's relative residual: min(forcing_max, sqrt(max |g|)) with g the scaled gradient.
  double forcing_max = 0.1;
  // The multigrid is rebuilt at the current positions before the next Newton step when a CG
  // solve needs more than this many times the iterations per decade of residual reduction of
  // the first solve after the build (plus 2); 0: rebuilt only when the constraints change.
  double multigrid_rebuild_slowdown = 2.0;
  AmgOptions amg;
};

struct NewtonCache;          // newton.hpp
class PreconditionerCache;   // preconditioner_cache.hpp
class DistributedEvaluator;  // distributed/distributed_evaluator.hpp

struct MinimiserOptions {
  MinimiserMethod method = MinimiserMethod::lbfgs;
  double force_tolerance = 1e-6;    // relative to force_scale
  double energy_tolerance = 1e-10;  // relative to max(sum of |terms| of the potential, E0)
  // N; <= 0: F0 = k_eff l_e, k_eff = 2 k_e + 8 k_f/sqrt(2) + 4 k_c of the polymer (eq. 4.95;
  // the run files' "characteristic force").
  double force_scale = 0.0;
  int max_iterations = 200000;  // inner iterations, all outer iterations together
  int max_outer_iterations = 50;
  MagnetizationCoupling coupling = MagnetizationCoupling::every_evaluation;
  int lbfgs_memory = 10;
  // L-BFGS only: initial inverse Hessian from `lbfgs_preconditioner` (false: the identity).
  bool precondition = true;
  LbfgsPreconditioner lbfgs_preconditioner = LbfgsPreconditioner::automatic;
  LbfgsHistoryPrecision lbfgs_history = LbfgsHistoryPrecision::automatic;
  // How the multilevel preconditioner scales the polymer's nodes (preconditioner.hpp: the
  // inverse of each node's 3 x 3 stiffness block, or of its diagonal); the rigid-particle
  // preconditioner alone, built at rest, has the diagonal either way.
  NodeScaling node_scaling = NodeScaling::blocks;
  // Whether the multilevel preconditioner solves the polymer between particles in contact
  // exactly (contact_gap_blocks.hpp).
  ContactGap contact_gap = ContactGap::exact;
  // multilevel and rigid_particles: where the preconditioner is kept between calls (a caller
  // relaxing many steps of one system keeps one; null: built anew in every call).
  std::shared_ptr<PreconditionerCache> preconditioner_cache;
  // With the multilevel preconditioner and a cache: the largest node displacement, in lattice
  // spacings, from the state the kept preconditioner was built at up to which a call keeps it
  // (preconditioner_cache.hpp); 0: built anew at every call's start. The run files' default
  // (SolverSpec) sets it for every 3D run.
  double preconditioner_reuse = 0.3;
  double max_step = 0.2;  // largest coordinate change per iteration, in units of l_e
  // Seed profile, lbfgs: inexact defect correction. The conservative phase stops once its
  // largest force is below correction_forcing x the largest difference between the seed's and
  // the neighbour's forces at the start, each correction pass once below correction_forcing x
  // the seed's largest force at its start; never below force_tolerance, and the last pass is
  // run to it (with the energy test). 0: each to force_tolerance (the passes' first form).
  // 0.1 took 1.5-1.65x fewer evaluations than 0 on the scaled-down Fig. 4.11 loop at n_d = 2
  // and 3 (docs/performance.md).
  double correction_forcing = 0.1;
  FireParameters fire;
  NewtonOptions newton;
  // newton: where the multigrid is kept between calls (a caller relaxing many steps of one
  // run keeps one; null: built anew in every call).
  std::shared_ptr<NewtonCache> newton_cache;
  // Told every convergence check's largest force (progress reports); changes nothing.
  RelaxationObserver observer;
  // lbfgs and fire: every evaluation split over the evaluator's MPI processes, each of which
  // calls minimise() on its own copy of the same system at the same time (docs/mpi.md);
  // null: this process alone.
  std::shared_ptr<DistributedEvaluator> distributed;

  void validate() const;  // throws std::invalid_argument naming the option
};

struct MinimiserResult {
  MinimiserStatus status = MinimiserStatus::max_iterations;
  bool converged = false;
  int iterations = 0;        // inner iterations (L-BFGS steps or FIRE steps)
  int outer_iterations = 0;  // magnetization re-solves between minimisations (alternating)
  bool switched_to_alternating = false;  // every_evaluation fell back to alternating
  bool forces_only_phase = false;        // seed: relaxed further to the seed's own forces
  bool finished_with_fire = false;       // lbfgs's line search failed; FIRE finished
  bool finished_with_lbfgs = false;      // newton's line search failed; L-BFGS went on
  int correction_passes = 0;             // seed: correction passes for its forces (L-BFGS)
  bool slope_only_fallback = false;      // seed: L-BFGS went on with the slope-only search
  std::int64_t evaluations = 0;          // energy + gradient evaluations
  std::int64_t krylov_iterations = 0;    // newton: CG iterations (Hessian products)
  // L-BFGS's preconditioner built at a state (the multilevel one): "built" at this call's
  // start, "kept" from an earlier call's (preconditioner_cache.hpp); "" where there is none.
  std::string state_preconditioner;
  double preconditioner_seconds = 0.0;    // newton: building the multigrid (0 when reused)
  double multigrid_seconds = 0.0;         // newton: applying it (V-cycles)
  double hessian_product_seconds = 0.0;   // newton: Hessian-vector products
  double centre_hessian_seconds = 0.0;    // newton: reduced centre Hessians
  double max_force = 0.0;                 // N, the convergence measure at the end
  double force_scale = 0.0;               // N
  double energy_change = 0.0;             // J, potential change over the last iteration
  Evaluation final;                       // energies at the end (current M)
  std::int64_t magnetization_solves = 0;  // during this call
  std::int64_t unconverged_magnetization_solves = 0;
};

// Relaxes system.positions() (free coordinates and rigid groups; held coordinates stay) and
// its magnetizations.
//
// Settings: system.settings() are the same on return as on entry, whether minimise() returns
// or throws. While it runs, the system evaluates under the minimiser's own rules, set through
// one scoped view (RelaxationRules in minimiser.cpp) that writes the caller's settings back
// whole when the call ends: MagnetizationUpdate follows options.coupling (every_evaluation, or
// manual for alternating and after the fallback to it; FIRE's frequency estimate holds M fixed),
// and the seed's CentreRule::centre_voxel is replaced by all_nodes during the conservative
// L-BFGS phase. The final state (positions, M, result.final) is at the caller's centre rule;
// M was last re-solved under the coupling's rule, so with alternating it may differ from what the
// caller's MagnetizationUpdate would give at the next evaluation.
MinimiserResult minimise(MessSystem& system, const MinimiserOptions& options = {});

// The convergence measure: max over free coordinates, rigid-group net forces and particle net
// forces of |dE/dx| (N), from a full gradient (3 x N).
double max_free_force(const MessSystem& system, const Eigen::Matrix3Xd& gradient);

}  // namespace mresim::mess
