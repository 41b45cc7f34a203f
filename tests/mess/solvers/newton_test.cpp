// Tests of the Newton-Krylov relaxation (newton.hpp) and its parts:
//  (a) the assembled elastic matrix (hessian_assembly.hpp) is the elastic Hessian, with
//      identity rows and columns on the coordinates that are not dofs of their own;
//  (b) the reduced centre Hessian (M following the centres) matches finite differences of the
//      centre gradient of a system whose M is re-solved at every evaluation;
//  (c) the solver's Hessian product in the free variables matches central differences of the
//      scaled objective's gradient (M re-solved), rigid groups included;
//  (d) one GAMG V-cycle preconditions CG on the pair's elastic Hessian to 1e-8 in a few tens
//      of iterations, far fewer than without it;
//  (e) newton relaxes a two-particle system in a field to the state L-BFGS finds (centres to
//      1e-6 l_e, potential to 1e-9 relative) in a handful of Newton steps; the seed profile's
//      non-conservative forces and a rigid group relax too; L-BFGS with Newton's multigrid as
//      its preconditioner reaches L-BFGS's state in fewer iterations.

#include "mresim/mess/solvers/newton.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "../support/mess_test_support.hpp"
#include "mresim/mess/solvers/amg_preconditioner.hpp"
#include "mresim/mess/solvers/hessian_assembly.hpp"
#include "mresim/mess/solvers/leapfrog.hpp"
#include "mresim/mess/solvers/minimiser.hpp"

namespace mess = mresim::mess;
namespace lat = mresim::lattice;
using mess::testing::perturbed;
using mess::testing::small_lattice;
using mess::testing::tesla;

namespace {

void tighten_magnetization_to_1e13(mess::MessSystem& sys) {
  sys.settings().magnetization.atol = 1e-13;
  sys.settings().magnetization.rtol = 1e-13;
  sys.settings().magnetization.max_fixed_point_iterations = 5000;
}

// Two n_d = 1 particles along z in a 7 x 7 x 13-cell box, 0.03 T along z, bottom face held,
// positions perturbed so that every Hessian block is generic.
mess::MessSystem pair_in_field(const char* profile = "physical") {
  mess::MessSystem sys = mess::MessSystem::make(
      small_lattice(mess::model_profile(profile), {7, 7, 13}, {{3, 3, 4}, {3, 3, 8}}),
      tesla(0.0, 0.0, 0.03), mess::model_profile(profile));
  tighten_magnetization_to_1e13(sys);
  mess::BoundaryConstraints c = mess::BoundaryConstraints::none(sys.node_count());
  c.fix_face(sys.lattice().shape, lat::Face::bottom, sys.lattice().positions);
  sys.set_constraints(c);
  return sys;
}

// The symmetric pair of relaxation_test.cpp: 7 x 7 x 15 cells, all faces held, particles
// 6 l_e apart along the 0.03 T field.
mess::MessSystem physical_symmetric_pair() {
  const mess::ModelProfile& profile = mess::model_profile("physical");
  mess::MessSystem sys = mess::MessSystem::make(
      small_lattice(profile, {7, 7, 15}, {{3, 3, 4}, {3, 3, 10}}), tesla(0.0, 0.0, 0.03), profile);
  tighten_magnetization_to_1e13(sys);
  mess::BoundaryConstraints c = mess::BoundaryConstraints::none(sys.node_count());
  for (const lat::Face f : {lat::Face::left, lat::Face::right, lat::Face::front, lat::Face::back,
                            lat::Face::bottom, lat::Face::top}) {
    c.fix_face(sys.lattice().shape, f, sys.lattice().positions);
  }
  sys.set_constraints(c);
  return sys;
}

// Two relaxations of the same system ended in the same state: centres to 1e-7 l_e, M to
// 1e-8 Ms, the potential to 1e-10 relative.
void expect_same_state(const mess::MessSystem& a, const mess::MinimiserResult& ra,
                       const mess::MessSystem& b, const mess::MinimiserResult& rb) {
  EXPECT_LT((a.particle_centres() - b.particle_centres()).cwiseAbs().maxCoeff(),
            1e-7 * a.length_scale());
  EXPECT_LT((a.magnetizations() - b.magnetizations()).cwiseAbs().maxCoeff(),
            1e-8 * a.model().particles.Ms);
  EXPECT_NEAR(rb.final.potential, ra.final.potential, 1e-10 * std::abs(ra.final.potential));
}

double max_abs(const Eigen::VectorXd& v) { return v.cwiseAbs().maxCoeff(); }

}  // namespace

TEST(MessNewton, ElasticMatrixIsTheElasticHessianWithIdentityOnConstrainedCoordinates) {
  mess::MessSystem sys = pair_in_field();
  sys.set_positions(perturbed(sys.positions(), 0.05 * sys.length_scale()));
  const Eigen::Index n = 3 * sys.node_count();
  const Eigen::SparseMatrix<double> h = sys.elastic_hessian();
  mess::ElasticMatrix a(sys.lattice());
  std::vector<std::uint8_t> all_free(static_cast<std::size_t>(n), 1);
  a.assemble(sys, all_free, 2.0);
  const Eigen::VectorXd x = Eigen::VectorXd::Random(n);
  const Eigen::VectorXd hx = 2.0 * (h * x);
  EXPECT_LT(max_abs(a.multiply(x) - hx), 1e-12 * max_abs(hx));
  // The interior has 27 neighbour blocks per node.
  EXPECT_EQ(a.row_length(sys.lattice().shape.node_index(3, 3, 6)), 81);

  // Coordinate 0 not free: its row and column are a multiple of the identity.
  std::vector<std::uint8_t> free = all_free;
  free[0] = 0;
  a.assemble(sys, free, 1.0);
  Eigen::VectorXd e0 = Eigen::VectorXd::Zero(n);
  e0[0] = 1.0;
  const Eigen::VectorXd column = a.multiply(e0);
  EXPECT_GT(column[0], 0.0);
  EXPECT_EQ(column.tail(n - 1).cwiseAbs().maxCoeff(), 0.0);
  Eigen::VectorXd y = x;
  y[0] = 0.0;
  const Eigen::VectorXd hy = h * y;
  Eigen::VectorXd ay = a.multiply(y);
  EXPECT_EQ(ay[0], 0.0);
  ay[0] = hy[0];
  EXPECT_LT(max_abs(ay - hy), 1e-12 * max_abs(hy));
}

TEST(MessNewton, ReducedCentreHessianMatchesDifferencesOfTheCentreGradient) {
  mess::MessSystem sys = pair_in_field();
  sys.settings().magnetization_update = mess::MagnetizationUpdate::every_evaluation;
  Eigen::Matrix3Xd g;
  (void)sys.evaluate(&g);
  const Eigen::MatrixXd k = sys.reduced_centre_hessian();
  ASSERT_EQ(k.rows(), 6);
  // Shift particle 1 along z by +-h (all its nodes: the centre moves by h), re-solve M, and
  // difference the centre gradient.
  const double h = 1e-3 * sys.length_scale();
  const Eigen::Matrix3Xd x0 = sys.positions();
  const auto centre_gradient_at = [&](double shift) {
    Eigen::Matrix3Xd x = x0;
    for (const std::int32_t node : sys.lattice().particle_nodes[1]) x(2, node) += shift;
    sys.set_positions(x);
    (void)sys.solve_magnetization();
    return sys.centre_gradient();
  };
  const Eigen::Matrix3Xd difference = (centre_gradient_at(h) - centre_gradient_at(-h)) / (2 * h);
  const Eigen::Map<const Eigen::VectorXd> column(difference.data(), 6);
  EXPECT_GT(std::abs(k(5, 5)), 0.0);
  EXPECT_LT(max_abs(k.col(5) - column), 1e-5 * max_abs(column));
  // The attraction along the field softens with distance (E ~ -C/r^3, d2E/dz_1^2 = -12 C/r^5).
  EXPECT_LT(k(5, 5), 0.0);
}

// The constant load of the seed's correction passes (minimiser.cpp): the loaded objective's
// gradient is the plain one plus the load on the free variables, its potential grows by
// load . (x - x(u_ref)) (so central differences of it match the gradient), and clear_load()
// gives the plain objective back.
TEST(MessObjective, ConstantLoadAddsItsGradientAndItsWork) {
  mess::MessSystem sys = pair_in_field();
  sys.settings().magnetization_update = mess::MagnetizationUpdate::every_evaluation;
  sys.set_positions(perturbed(sys.positions(), 0.02 * sys.length_scale()));
  const double f0 = mess::LeapfrogScales::of(sys.lattice()).k_eff * sys.length_scale();
  const mess::DofMap map(sys.constraints(), sys.positions(), sys.length_scale());
  mess::detail::Objective f(sys, map, f0);
  const Eigen::VectorXd u = map.to_dofs(sys.positions());
  Eigen::VectorXd plain;
  const double phi_plain = f(u, plain);
  const Eigen::Matrix3Xd plain_full = f.full_gradient();
  // A load on every node (3 x N, J/m), of the size of F0, as the seed's centre forces are.
  const Eigen::Matrix3Xd load = perturbed(Eigen::Matrix3Xd::Zero(3, sys.node_count()), f0);
  const Eigen::VectorXd u_ref = u + 0.1 * Eigen::VectorXd::Ones(u.size());
  f.set_load(load, u_ref);
  Eigen::VectorXd loaded;
  const double phi_loaded = f(u, loaded);
  const Eigen::VectorXd load_dofs = map.reduce(load) / f.energy_scale();
  EXPECT_LT(max_abs(loaded - plain - load_dofs), 1e-12 * max_abs(plain));
  EXPECT_NEAR(phi_loaded - phi_plain, load_dofs.dot(u - u_ref), 1e-12 * std::abs(phi_plain));
  EXPECT_LT((f.full_gradient() - plain_full - load).cwiseAbs().maxCoeff(), 1e-12 * f0);
  // Central differences of the loaded potential along a direction of unit size.
  const Eigen::Matrix3Xd unit = perturbed(Eigen::Matrix3Xd::Zero(3, sys.node_count()), 1.0, 11);
  const Eigen::VectorXd v = map.reduce(unit) / sys.length_scale();  // up to 1 per dof
  const double h = 1e-5;
  Eigen::VectorXd scratch;
  const double slope = (f(u + h * v, scratch) - f(u - h * v, scratch)) / (2 * h);
  EXPECT_NEAR(slope, loaded.dot(v), 1e-5 * std::abs(loaded.dot(v)));
  f.clear_load();
  Eigen::VectorXd again;
  // (M is re-solved from where the last evaluation left it: equal to its tolerance.)
  EXPECT_NEAR(f(u, again), phi_plain, 1e-12 * std::abs(phi_plain));
  EXPECT_LT(max_abs(again - plain), 1e-9 * max_abs(plain));
}

// The seed's load acts on the particle nodes only, and the objective keeps it there: the work
// load . (u - u_ref) over those components, the same at a line search's trial point
// u + alpha d as at that point formed whole (to the magnetization's tolerance).
TEST(MessObjective, LoadOnAFewNodesAddsItsWorkAlongALine) {
  mess::MessSystem sys = pair_in_field();
  sys.set_positions(perturbed(sys.positions(), 0.02 * sys.length_scale()));
  const double f0 = mess::LeapfrogScales::of(sys.lattice()).k_eff * sys.length_scale();
  const mess::DofMap map(sys.constraints(), sys.positions(), sys.length_scale());
  mess::detail::Objective f(sys, map, f0);
  const Eigen::VectorXd u = map.to_dofs(sys.positions());
  // A direction of up to 0.01 per dof (units of l_e).
  const Eigen::VectorXd d =
      map.reduce(perturbed(Eigen::Matrix3Xd::Zero(3, sys.node_count()), 0.01, 4)) /
      sys.length_scale();
  Eigen::Matrix3Xd load = Eigen::Matrix3Xd::Zero(3, sys.node_count());
  for (const Eigen::Index n : {Eigen::Index{3}, Eigen::Index{17}, sys.node_count() - 2}) {
    load.col(n) = Eigen::Vector3d(0.3, -1.1, 0.7) * f0 * static_cast<double>(n % 5 + 1);
  }
  const Eigen::VectorXd u_ref = u - 0.2 * d;
  const Eigen::VectorXd trial = u + 0.5 * d;
  Eigen::VectorXd plain;
  const double phi_plain = f(trial, plain);
  f.set_load(load, u_ref);
  Eigen::VectorXd at_trial;
  const double phi_trial = f(trial, at_trial);
  Eigen::VectorXd along;
  const double phi_along = f.along(u, 0.5, d, along);
  const Eigen::VectorXd load_dofs = map.reduce(load) / f.energy_scale();
  ASSERT_GT(max_abs(load_dofs), 0.0);
  const double work = load_dofs.dot(trial - u_ref);
  EXPECT_GT(std::abs(work), 1e-6 * std::abs(phi_plain));
  EXPECT_NEAR(phi_trial - phi_plain, work, 1e-12 * std::abs(phi_plain));
  // (M is re-solved at each evaluation from where the last one left it: equal to its tolerance.)
  EXPECT_NEAR(phi_along, phi_trial, 1e-13 * std::abs(phi_trial));
  EXPECT_LT(max_abs(along - at_trial), 1e-12 * max_abs(at_trial));
  EXPECT_LT(max_abs(at_trial - plain - load_dofs), 1e-12 * max_abs(plain));
}

TEST(MessNewton, HessianProductMatchesDifferencesOfTheObjectiveGradient) {
  for (const bool with_group : {false, true}) {
    mess::MessSystem sys = pair_in_field();
    if (with_group) {
      mess::BoundaryConstraints c = sys.constraints();
      const std::vector<int> top = lat::face_nodes(sys.lattice().shape, lat::Face::top);
      c.add_rigid_group(std::vector<std::int32_t>(top.begin(), top.end()));
      sys.set_constraints(c);
    }
    sys.settings().magnetization_update = mess::MagnetizationUpdate::every_evaluation;
    sys.set_positions(perturbed(sys.positions(), 0.02 * sys.length_scale()));
    const double f0 = mess::LeapfrogScales::of(sys.lattice()).k_eff * sys.length_scale();
    const mess::DofMap map(sys.constraints(), sys.positions(), sys.length_scale());
    mess::detail::Objective f(sys, map, f0);
    const Eigen::VectorXd u = map.to_dofs(sys.positions());
    Eigen::VectorXd g;
    (void)f(u, g);
    mess::detail::NewtonSolver newton(sys, map, f0, mess::NewtonOptions{});
    newton.update_centre_hessian();
    const Eigen::VectorXd v = Eigen::VectorXd::Random(map.size());
    const Eigen::VectorXd hv = newton.hessian_product(v);
    const double h = 1e-5;
    Eigen::VectorXd gp;
    Eigen::VectorXd gm;
    (void)f(u + h * v, gp);
    (void)f(u - h * v, gm);
    const Eigen::VectorXd fd = (gp - gm) / (2 * h);
    EXPECT_LT(max_abs(hv - fd), 1e-6 * max_abs(fd)) << "rigid group: " << with_group;
  }
}

TEST(MessNewton, MultigridPreconditionsTheElasticHessian) {
  mess::MessSystem sys = pair_in_field();
  const mess::DofMap map(sys.constraints(), sys.positions(), sys.length_scale());
  mess::ElasticMatrix a(sys.lattice());
  a.assemble(sys, map.own_dof_mask(), 1.0 / sys.lattice().polymer.springs.edge);
  const mess::AmgPreconditioner amg(a, sys.positions() / sys.length_scale());
  EXPECT_GE(amg.levels(), 2);
  // CG on A x = b (b: a pull on the upper particle), with and without the V-cycle.
  Eigen::VectorXd b = Eigen::VectorXd::Zero(a.rows());
  for (const std::int32_t n : sys.lattice().particle_nodes[1]) b[3 * n + 2] = 1.0;
  const auto cg_iterations = [&](bool precondition) {
    Eigen::VectorXd x = Eigen::VectorXd::Zero(a.rows());
    Eigen::VectorXd r = b;
    Eigen::VectorXd z;
    const auto apply = [&](const Eigen::VectorXd& in, Eigen::VectorXd& out) {
      if (precondition) {
        amg.apply(in, out);
      } else {
        out = in;
      }
    };
    apply(r, z);
    Eigen::VectorXd p = z;
    double rz = r.dot(z);
    for (int k = 1; k <= 5000; ++k) {
      const Eigen::VectorXd ap = a.multiply(p);
      const double alpha = rz / p.dot(ap);
      x += alpha * p;
      r -= alpha * ap;
      if (r.norm() <= 1e-8 * b.norm()) return k;
      apply(r, z);
      const double rz_next = r.dot(z);
      p = z + (rz_next / rz) * p;
      rz = rz_next;
    }
    return 5001;
  };
  const int with_amg = cg_iterations(true);
  const int without = cg_iterations(false);
  EXPECT_LE(with_amg, 60);
  EXPECT_GT(without, 4 * with_amg);
}

TEST(MessNewton, RelaxesThePairToTheStateLbfgsFinds) {
  mess::MessSystem a = physical_symmetric_pair();
  mess::MessSystem b = a;
  mess::MinimiserOptions opt;
  opt.force_tolerance = 1e-9;
  const mess::MinimiserResult rl = mess::minimise(a, opt);
  opt.method = mess::MinimiserMethod::newton;
  const mess::MinimiserResult rn = mess::minimise(b, opt);
  ASSERT_TRUE(rl.converged) << mess::to_string(rl.status);
  ASSERT_TRUE(rn.converged) << mess::to_string(rn.status);
  EXPECT_FALSE(rn.finished_with_lbfgs);
  EXPECT_LE(rn.iterations, 10);
  EXPECT_LT(rn.iterations, rl.iterations / 5);
  EXPECT_GT(rn.krylov_iterations, rn.iterations);
  expect_same_state(a, rl, b, rn);
}

// L-BFGS with Newton's multigrid as its initial inverse Hessian (LbfgsPreconditioner::
// multigrid) reaches the same state as with the default preconditioner, in fewer iterations
// (the route measured in mess_scaling_bench).
TEST(MessNewton, MultigridPreconditionedLbfgsReachesTheSameStateInFewerIterations) {
  mess::MessSystem a = physical_symmetric_pair();
  mess::MessSystem b = a;
  mess::MinimiserOptions opt;
  opt.force_tolerance = 1e-9;
  const mess::MinimiserResult rigid = mess::minimise(a, opt);
  opt.lbfgs_preconditioner = mess::LbfgsPreconditioner::multigrid;
  const mess::MinimiserResult multigrid = mess::minimise(b, opt);
  ASSERT_TRUE(rigid.converged) << mess::to_string(rigid.status);
  ASSERT_TRUE(multigrid.converged) << mess::to_string(multigrid.status);
  EXPECT_FALSE(multigrid.finished_with_fire);
  EXPECT_GT(multigrid.multigrid_seconds, 0.0);  // the V-cycle was applied
  EXPECT_LT(multigrid.iterations, rigid.iterations / 2)
      << multigrid.iterations << " against " << rigid.iterations;
  expect_same_state(a, rigid, b, multigrid);
}

// Closer (4 l_e apart, bottom face held only), the pair draws together strongly; L-BFGS
// stalls above 1e-7 k_eff l_e here (about 150,000 iterations, measured), Newton converges.
TEST(MessNewton, ConvergesWhereThePairDrawsTogether) {
  mess::MessSystem sys = pair_in_field();
  const double s0 = (sys.particle_centres().col(1) - sys.particle_centres().col(0)).norm();
  mess::MinimiserOptions opt;
  opt.force_tolerance = 1e-9;
  opt.method = mess::MinimiserMethod::newton;
  const mess::MinimiserResult r = mess::minimise(sys, opt);
  ASSERT_TRUE(r.converged) << mess::to_string(r.status);
  EXPECT_FALSE(r.finished_with_lbfgs);
  EXPECT_LE(r.iterations, 40);
  EXPECT_LE(r.max_force, 1e-9 * r.force_scale);
  const Eigen::Matrix3Xd c = sys.particle_centres();
  EXPECT_LT((c.col(1) - c.col(0)).norm(), s0 - 0.01 * sys.length_scale());
}

// The same pair drawn together from a multigrid built at the start: once the gap has been
// squeezed, CG slows down with that multigrid, and it is rebuilt where the pair now is; the
// state reached is the same as with the first multigrid kept throughout, in fewer CG
// iterations.
TEST(MessNewton, RebuildsTheMultigridWhenConjugateGradientsSlowDown) {
  mess::MessSystem rebuilt = pair_in_field();
  mess::MessSystem kept = rebuilt;
  mess::MinimiserOptions opt;
  opt.force_tolerance = 1e-9;
  opt.method = mess::MinimiserMethod::newton;
  opt.newton_cache = std::make_shared<mess::NewtonCache>();
  const mess::MinimiserResult r = mess::minimise(rebuilt, opt);
  ASSERT_TRUE(r.converged) << mess::to_string(r.status);
  EXPECT_GE(opt.newton_cache->setups, 2);

  opt.newton_cache = std::make_shared<mess::NewtonCache>();
  opt.newton.multigrid_rebuild_slowdown = 0.0;
  const mess::MinimiserResult k = mess::minimise(kept, opt);
  ASSERT_TRUE(k.converged) << mess::to_string(k.status);
  EXPECT_EQ(opt.newton_cache->setups, 1);
  EXPECT_LT(r.krylov_iterations, k.krylov_iterations);
  EXPECT_LT((rebuilt.particle_centres() - kept.particle_centres()).cwiseAbs().maxCoeff(),
            1e-6 * rebuilt.length_scale());
}

TEST(MessNewton, SeedProfileAndRigidGroupRelax) {
  {
    mess::MessSystem a = pair_in_field("seed");
    mess::MessSystem b = a;
    mess::MinimiserOptions opt;
    opt.force_tolerance = 1e-8;
    ASSERT_TRUE(mess::minimise(a, opt).converged);
    opt.method = mess::MinimiserMethod::newton;
    const mess::MinimiserResult r = mess::minimise(b, opt);
    ASSERT_TRUE(r.converged) << mess::to_string(r.status);
    EXPECT_LT((a.particle_centres() - b.particle_centres()).cwiseAbs().maxCoeff(),
              1e-6 * a.length_scale());
  }
  {
    const lat::Lattice l = small_lattice(mess::model_profile("physical"), {4, 4, 4});
    mess::BoundaryConstraints c = mess::BoundaryConstraints::none(l.node_count());
    c.fix_face(l.shape, lat::Face::bottom, l.positions);
    const std::vector<int> top = lat::face_nodes(l.shape, lat::Face::top);
    c.add_rigid_group(std::vector<std::int32_t>(top.begin(), top.end()));
    Eigen::Matrix3Xd force = Eigen::Matrix3Xd::Zero(3, l.node_count());
    for (const int n : top) force(0, n) = 1e-3 * l.polymer.springs.edge * l.element_length;
    mess::MessSystem a =
        mess::MessSystem::make(l, Eigen::Vector3d::Zero(), mess::model_profile("physical"));
    a.set_constraints(c);
    a.set_applied_forces(force);
    mess::MessSystem b = a;
    mess::MinimiserOptions opt;
    opt.force_tolerance = 1e-10;
    ASSERT_TRUE(mess::minimise(a, opt).converged);
    opt.method = mess::MinimiserMethod::newton;
    const mess::MinimiserResult r = mess::minimise(b, opt);
    ASSERT_TRUE(r.converged) << mess::to_string(r.status);
    EXPECT_LE(r.iterations, 5);  // nearly linear: Newton converges in a few steps
    const double shift = a.positions()(0, top[0]) - l.positions(0, top[0]);
    EXPECT_GT(shift, 0.0);
    EXPECT_LT((a.positions() - b.positions()).cwiseAbs().maxCoeff(), 1e-7 * shift);
  }
}

// The multigrid kept in a NewtonCache serves later calls with the same constraints (a run's
// field steps) and is rebuilt when they change; reuse changes no result beyond the tolerance.
TEST(MessNewton, CacheKeepsTheMultigridAcrossCallsWithTheSameConstraints) {
  mess::MessSystem sys = pair_in_field();
  mess::MessSystem fresh = sys;
  mess::MinimiserOptions opt;
  opt.method = mess::MinimiserMethod::newton;
  opt.force_tolerance = 1e-9;
  opt.newton_cache = std::make_shared<mess::NewtonCache>();
  ASSERT_TRUE(mess::minimise(sys, opt).converged);
  // Built at the start, and again once the pair had drawn together (the test above).
  const int first_call_setups = opt.newton_cache->setups;
  EXPECT_GE(first_call_setups, 1);
  sys.set_applied_field(tesla(0.0, 0.0, 0.04));
  const mess::MinimiserResult reused = mess::minimise(sys, opt);
  ASSERT_TRUE(reused.converged);
  EXPECT_EQ(opt.newton_cache->setups, first_call_setups);
  EXPECT_EQ(reused.preconditioner_seconds, 0.0);
  // The same two steps with a multigrid built for each call end in the same state.
  mess::MinimiserOptions own = opt;
  own.newton_cache = nullptr;
  ASSERT_TRUE(mess::minimise(fresh, own).converged);
  fresh.set_applied_field(tesla(0.0, 0.0, 0.04));
  ASSERT_TRUE(mess::minimise(fresh, own).converged);
  EXPECT_LT((sys.particle_centres() - fresh.particle_centres()).cwiseAbs().maxCoeff(),
            1e-7 * sys.length_scale());
  // Other constraints (the top face held too): a new multigrid.
  mess::BoundaryConstraints c = sys.constraints();
  c.fix_face(sys.lattice().shape, lat::Face::top, sys.positions());
  sys.set_constraints(c);
  ASSERT_TRUE(mess::minimise(sys, opt).converged);
  EXPECT_GE(opt.newton_cache->setups, first_call_setups + 1);
}
