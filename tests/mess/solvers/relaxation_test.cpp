// Tests of the relaxation methods of the 3D model (minimiser.hpp, leapfrog.hpp):
//  (a) a particle-free block under affine simple shear of its whole boundary relaxes to the
//      affine state with energy density G gamma^2/2: G = E/(2(1+nu)) (physical), 0.4 E (seed);
//  (b) the minimisers and the damped leapfrog reach the same configuration of a two-particle
//      system in a field (timing comparison: bench/mess_relax_bench.cpp);
//  (c) two particles along z in a mirror-symmetric box: a field along z pulls them together,
//      a field along x pushes them apart, and the relaxed state keeps the mirror symmetry;
// plus the scales of the leapfrog, its seed tolerance and rigid groups, and independence of
// the thread count.

#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <numbers>

#include "../support/mess_test_support.hpp"
#include "mresim/mess/solvers/leapfrog.hpp"
#include "mresim/mess/solvers/minimiser.hpp"

namespace mess = mresim::mess;
namespace lat = mresim::lattice;
using mess::testing::small_lattice;
using mess::testing::tesla;

namespace {

constexpr lat::Face kFaces[] = {lat::Face::left, lat::Face::right,  lat::Face::front,
                                lat::Face::back, lat::Face::bottom, lat::Face::top};

// All six faces held at `target`.
mess::BoundaryConstraints all_faces_held(const lat::Lattice& l, const Eigen::Matrix3Xd& target) {
  mess::BoundaryConstraints c = mess::BoundaryConstraints::none(l.node_count());
  for (const lat::Face f : kFaces) c.fix_face(l.shape, f, target);
  return c;
}

// The magnetization solved far below the dissertation's tolerance, so that the relaxed state
// is defined to much better than the solver's tolerance band (docs/mess-solvers.md).
void tighten_magnetization(mess::MessSystem& sys) {
  sys.settings().magnetization.atol = 1e-11;
  sys.settings().magnetization.rtol = 1e-11;
  sys.settings().magnetization.max_fixed_point_iterations = 2000;
}

// Two n_d = 1 particles (3 voxels across) on the z axis of a 7 x 7 x 15-cell box, centres in
// cells z = 4 and 10 (three polymer voxels between them), mirror-symmetric about z = 7.5 l_e
// and about the box's x and y mid-planes. All faces held.
mess::MessSystem symmetric_pair(const mess::ModelProfile& profile, const Eigen::Vector3d& H) {
  mess::MessSystem sys = mess::MessSystem::make(
      small_lattice(profile, {7, 7, 15}, {{3, 3, 4}, {3, 3, 10}}), H, profile);
  sys.set_constraints(all_faces_held(sys.lattice(), sys.lattice().positions));
  return sys;
}

// The symmetric pair, seed profile, at 30 mT along the pair, M solved tightly.
mess::MessSystem seed_pair_at_30_mT() {
  mess::MessSystem sys = symmetric_pair(mess::model_profile("seed"), tesla(0.0, 0.0, 0.03));
  tighten_magnetization(sys);
  return sys;
}

double separation(const mess::MessSystem& sys) {
  const Eigen::Matrix3Xd c = sys.particle_centres();
  return (c.col(1) - c.col(0)).norm() / sys.length_scale();
}

// Largest deviation (units of l_e) from mirror symmetry about the box's mid-plane normal to
// `axis`: node (i, j, k) against its mirror image.
double mirror_asymmetry(const mess::MessSystem& sys, int axis) {
  const lat::GridShape& shape = sys.lattice().shape;
  const double length = sys.lattice().box_lengths()[axis];
  const Eigen::Matrix3Xd& x = sys.positions();
  double worst = 0.0;
  for (int n = 0; n < shape.node_count(); ++n) {
    auto c = shape.node_coordinates(n);
    c[axis] = shape.nodes[axis] - 1 - c[axis];
    Eigen::Vector3d image = x.col(shape.node_index(c[0], c[1], c[2]));
    image[axis] = length - image[axis];
    worst = std::max(worst, (x.col(n) - image).cwiseAbs().maxCoeff());
  }
  return worst / sys.length_scale();
}

}  // namespace

// (a) The boundary is displaced affinely (x += gamma z on all six faces: bottom held, top moved
// by gamma H, sides on the affine field, the original's strain_simple_shearing); the interior
// starts undeformed and relaxes. Affine shear is the exact equilibrium, and its energy per volume
// is G gamma^2/2 up to O(gamma^2) relative (the springs are geometrically nonlinear).
TEST(MessSolvers, ParticleFreeBlockShearsWithTheProfilesModulus) {
  const double gamma = 1e-4;
  const double E = 9.0e3;
  for (const std::string_view name : {"physical", "seed"}) {
    const mess::ModelProfile& profile = mess::model_profile(name);
    const lat::Lattice l = small_lattice(profile, {5, 5, 5});  // 6 x 6 x 6 nodes
    ASSERT_EQ(l.node_count(), 216);
    Eigen::Matrix3Xd affine = l.positions;
    affine.row(0) += gamma * l.positions.row(2);
    const double expected_g = profile.shear_modulus_rule == lat::ShearModulusRule::two_fifths_youngs
                                  ? 3600.0
                                  : E / (2.0 * 1.47);
    for (const mess::MinimiserMethod method :
         {mess::MinimiserMethod::lbfgs, mess::MinimiserMethod::fire}) {
      mess::MessSystem sys = mess::MessSystem::make(l, Eigen::Vector3d::Zero(), profile);
      sys.set_constraints(all_faces_held(l, affine));
      mess::MinimiserOptions opt;
      opt.method = method;
      opt.force_tolerance = 1e-10;
      const mess::MinimiserResult r = mess::minimise(sys, opt);
      ASSERT_TRUE(r.converged) << mess::to_string(method) << " " << mess::to_string(r.status);
      EXPECT_LT(r.max_force, 1e-10 * r.force_scale);
      const double density = r.final.energies.total() / l.box_lengths().prod();
      EXPECT_NEAR(density, 0.5 * expected_g * gamma * gamma, 1e-6 * density)
          << profile.name << " " << mess::to_string(method);
      // The interior is affine to 1e-5 of the shear displacement per l_e.
      EXPECT_LT((sys.positions() - affine).cwiseAbs().maxCoeff(), 1e-5 * gamma * l.element_length);
    }
  }
}

// The leapfrog reaches the same affine state (physical profile, original settings but shorter
// rounds and a tighter tolerance).
TEST(MessSolvers, LeapfrogRelaxesTheShearedBlock) {
  const double gamma = 1e-3;
  const lat::Lattice l = small_lattice(mess::model_profile("physical"), {5, 5, 5});
  Eigen::Matrix3Xd affine = l.positions;
  affine.row(0) += gamma * l.positions.row(2);
  mess::MessSystem sys =
      mess::MessSystem::make(l, Eigen::Vector3d::Zero(), mess::model_profile("physical"));
  sys.set_constraints(all_faces_held(l, affine));
  mess::LeapfrogOptions opt;
  opt.steps_per_round = 1000;
  opt.tolerance = 1e-9;
  const mess::LeapfrogResult r = mess::relax_leapfrog(sys, opt);
  ASSERT_TRUE(r.converged) << mess::to_string(r.status);
  EXPECT_GE(r.rounds, 4);
  EXPECT_LT((sys.positions() - affine).cwiseAbs().maxCoeff(), 1e-6 * gamma * l.element_length);
}

// (b) Same local minimum from the minimisers and from the damped leapfrog, for two particles
// along a 0.1 T field (they close the polymer gap and end in WCA contact). Stated tolerance:
// every node within 1e-6 l_e, particle centres within 1e-7 l_e of the L-BFGS result (the
// leapfrog stops at mean |a| < 1e-6, which bounds its residual displacement).
TEST(MessSolvers, MinimiserAndLeapfrogReachTheSameState) {
  const auto make = [] {
    mess::MessSystem sys = mess::MessSystem::make(
        small_lattice(mess::model_profile("physical"), {7, 7, 12}, {{3, 3, 3}, {3, 3, 8}}),
        tesla(0.0, 0.0, 0.1), mess::model_profile("physical"));
    sys.set_constraints(all_faces_held(sys.lattice(), sys.lattice().positions));
    tighten_magnetization(sys);
    return sys;
  };
  mess::MessSystem ref = make();
  mess::MinimiserOptions mo;
  mo.force_tolerance = 1e-9;
  const mess::MinimiserResult rm = mess::minimise(ref, mo);
  ASSERT_TRUE(rm.converged) << mess::to_string(rm.status);
  EXPECT_EQ(rm.unconverged_magnetization_solves, 0);
  EXPECT_LT(separation(ref), 5.0 - 1.0);  // attracted into contact from 5 l_e
  EXPECT_GT(separation(ref), 3.0);        // WCA: r_min = 2R + 100 nm = 3.1 l_e

  mess::MessSystem fire = make();
  mess::MinimiserOptions fo = mo;
  fo.method = mess::MinimiserMethod::fire;
  const mess::MinimiserResult rf = mess::minimise(fire, fo);
  ASSERT_TRUE(rf.converged) << mess::to_string(rf.status);
  EXPECT_LT((fire.positions() - ref.positions()).cwiseAbs().maxCoeff() / ref.length_scale(), 1e-6);

  mess::MessSystem leap = make();
  mess::LeapfrogOptions lo;
  lo.time_step = 3e-3;  // n_d = 1: the original's 5e-3 is beyond the stability limit
  lo.steps_per_round = 1500;
  lo.tolerance = 1e-6;
  const mess::LeapfrogResult rl = mess::relax_leapfrog(leap, lo);
  ASSERT_TRUE(rl.converged) << mess::to_string(rl.status);
  EXPECT_EQ(rl.unconverged_magnetization_solves, 0);
  const double le = ref.length_scale();
  EXPECT_LT((leap.positions() - ref.positions()).cwiseAbs().maxCoeff() / le, 1e-6);
  EXPECT_LT((leap.particle_centres() - ref.particle_centres()).cwiseAbs().maxCoeff() / le, 1e-7);
  // The minimiser needs far fewer force evaluations (timings: bench/mess_relax_bench.cpp).
  EXPECT_LT(20 * rm.evaluations, rl.steps);
}

// (c) Field along the pair: attraction; across it: repulsion. Both keep the box's mirror
// symmetry about z = L/2 (and the lateral ones). 30 mT along z: the pair closes from 6 to about
// 5.4 l_e. (From about 50 mT on it collapses into WCA contact, squeezing the polymer between
// the particles to a fraction of a voxel; that layer then buckles sideways and the relaxed
// state is no longer mirror-symmetric: the symmetric state is a saddle there.)
TEST(MessSolvers, SymmetricPairAttractsAlongAndRepelsAcrossTheField) {
  for (const bool along : {true, false}) {
    mess::MessSystem sys = symmetric_pair(mess::model_profile("physical"),
                                          along ? tesla(0.0, 0.0, 0.03) : tesla(0.15, 0.0, 0.0));
    tighten_magnetization(sys);
    const double s0 = separation(sys);
    ASSERT_NEAR(s0, 6.0, 1e-12);
    ASSERT_LT(mirror_asymmetry(sys, 2), 1e-12);
    mess::MinimiserOptions opt;
    opt.force_tolerance = 1e-9;
    const mess::MinimiserResult r = mess::minimise(sys, opt);
    ASSERT_TRUE(r.converged) << mess::to_string(r.status);
    const double s = separation(sys);
    if (along) {
      EXPECT_LT(s, s0 - 0.3) << "attraction";
      EXPECT_GT(s, 4.0);  // not in contact
    } else {
      EXPECT_GT(s, s0 + 0.1) << "repulsion";
    }
    // Mirror symmetry about the mid-plane z = L/2 and about the lateral mid-planes (the field
    // along x breaks only the x mirror of the magnetization, not of the centres' forces).
    EXPECT_LT(mirror_asymmetry(sys, 2), 1e-9) << along;
    EXPECT_LT(mirror_asymmetry(sys, 1), 1e-9) << along;
    if (along) {
      EXPECT_LT(mirror_asymmetry(sys, 0), 1e-9);
    }
    // Both particles move by the same amount in opposite directions along z only.
    const Eigen::Matrix3Xd c = sys.particle_centres();
    const Eigen::Vector3d mid = 0.5 * sys.lattice().box_lengths();
    EXPECT_NEAR(c(2, 0) + c(2, 1), 2.0 * mid.z(), 1e-9 * sys.length_scale());
    for (int p = 0; p < 2; ++p) {
      EXPECT_NEAR(c(1, p), mid.y(), 1e-9 * sys.length_scale());
      if (along) {
        EXPECT_NEAR(c(0, p), mid.x(), 1e-9 * sys.length_scale());
      }
    }
  }
}

// The seed profile's non-conservative spreading (centre = centre voxel) relaxes with FIRE and
// ends where L-BFGS on the same forces does, to the particles' internal deformation.
TEST(MessSolvers, SeedProfileRelaxesWithBothMethods) {
  mess::MessSystem a = seed_pair_at_30_mT();
  mess::MessSystem b = seed_pair_at_30_mT();
  mess::MinimiserOptions opt;
  opt.force_tolerance = 1e-8;
  const mess::MinimiserResult ra = mess::minimise(a, opt);
  opt.method = mess::MinimiserMethod::fire;
  const mess::MinimiserResult rb = mess::minimise(b, opt);
  ASSERT_TRUE(ra.converged) << mess::to_string(ra.status);
  ASSERT_TRUE(rb.converged) << mess::to_string(rb.status);
  // L-BFGS met the seed's own forces after its conservative phase (the correction passes),
  // without FIRE.
  EXPECT_TRUE(ra.forces_only_phase);
  EXPECT_FALSE(ra.finished_with_fire);
  EXPECT_LE(ra.max_force, 1e-8 * ra.force_scale);
  EXPECT_LT((a.particle_centres() - b.particle_centres()).cwiseAbs().maxCoeff() / a.length_scale(),
            1e-5);
  EXPECT_LT(separation(a), 6.0 - 0.05);
}

// Inexact correction passes (MinimiserOptions::correction_forcing: each inner run only to a
// fraction of what the next pass corrects) end in the state the exact passes reach, within the
// force tolerance; the last pass is a tight one. (On this 1.6k-node pair both need 110
// iterations; the saving grows with the lattice: mess_scaling_bench prints lbfgs-exact
// against lbfgs, docs/performance.md.)
TEST(MessSolvers, InexactCorrectionPassesReachTheExactPassesState) {
  mess::MessSystem exact = seed_pair_at_30_mT();
  mess::MessSystem inexact = seed_pair_at_30_mT();
  mess::MinimiserOptions opt;
  opt.force_tolerance = 1e-8;
  opt.correction_forcing = 0.0;
  const mess::MinimiserResult re = mess::minimise(exact, opt);
  opt.correction_forcing = mess::MinimiserOptions{}.correction_forcing;
  ASSERT_GT(opt.correction_forcing, 0.0);  // the default is the inexact form
  const mess::MinimiserResult ri = mess::minimise(inexact, opt);
  ASSERT_TRUE(re.converged) << mess::to_string(re.status);
  ASSERT_TRUE(ri.converged) << mess::to_string(ri.status);
  EXPECT_FALSE(ri.slope_only_fallback);
  EXPECT_FALSE(ri.finished_with_fire);
  EXPECT_LE(ri.max_force, 1e-8 * ri.force_scale);
  EXPECT_GE(ri.correction_passes, re.correction_passes);
  // Both states meet the force tolerance 1e-8 F0 on springs of stiffness ~ k_eff: they agree
  // to ~1e-8 l_e over the few stiff modes that dominate the particles' positions.
  EXPECT_LT((exact.particle_centres() - inexact.particle_centres()).cwiseAbs().maxCoeff() /
                exact.length_scale(),
            1e-6);
  EXPECT_NEAR(ri.final.potential, re.final.potential, 1e-8 * std::abs(re.final.potential));
}

TEST(MessSolvers, LeapfrogScalesFollowSection426) {
  const lat::Lattice l = small_lattice(mess::model_profile("seed"), {4, 4, 4});
  const mess::LeapfrogScales s = mess::LeapfrogScales::of(l);
  const double le = l.element_length;
  const double E = 9.0e3;
  // Seed constants (A = 1): k_e = 22/35 E l_e, k_f = k_c = 6/35 E l_e.
  const double k_eff = (2.0 * 22.0 + 8.0 * 6.0 / std::sqrt(2.0) + 4.0 * 6.0) / 35.0 * E * le;
  EXPECT_NEAR(s.k_eff, k_eff, 1e-12 * k_eff);
  const double m_c = 965.0 * le * le * le;
  EXPECT_NEAR(s.mass, m_c, 1e-12 * m_c);
  EXPECT_NEAR(s.time, 2.0 * std::numbers::pi * std::sqrt(m_c / k_eff), 1e-12 * s.time);
  EXPECT_NEAR(s.beta, s.time * s.time / le, 1e-12 * s.beta);
}

// docs/original-code.md#convergence: about 4.97e-4 for 42 x 42 x 83 nodes and 2.67e-4 for
// 23 x 23 x 44 at dt = 5e-3.
TEST(MessSolvers, SeedConvergenceToleranceMatchesTheOriginal) {
  lat::Lattice l;
  l.shape.nodes = {42, 42, 83};
  EXPECT_NEAR(mess::seed_convergence_tolerance(l, 5e-3), 4.97e-4, 0.01e-4);
  l.shape.nodes = {23, 23, 44};
  EXPECT_NEAR(mess::seed_convergence_tolerance(l, 5e-3), 2.67e-4, 0.01e-4);
}

// A face free to translate as a rigid unit (strain runs at zero strain): pulled by a net force
// on a block held at the bottom, the top face moves as one and the minimiser and the leapfrog
// with the total-force rule agree.
TEST(MessSolvers, RigidGroupTranslatesAsOne) {
  const lat::Lattice l = small_lattice(mess::model_profile("physical"), {4, 4, 4});
  mess::BoundaryConstraints c = mess::BoundaryConstraints::none(l.node_count());
  c.fix_face(l.shape, lat::Face::bottom, l.positions);
  const std::vector<int> top = lat::face_nodes(l.shape, lat::Face::top);
  c.add_rigid_group(std::vector<std::int32_t>(top.begin(), top.end()));
  Eigen::Matrix3Xd f = Eigen::Matrix3Xd::Zero(3, l.node_count());
  const double shear_force = 1e-3 * l.polymer.springs.edge * l.element_length;
  for (const int n : top) f(0, n) = shear_force;
  mess::MessSystem a =
      mess::MessSystem::make(l, Eigen::Vector3d::Zero(), mess::model_profile("physical"));
  a.set_constraints(c);
  a.set_applied_forces(f);
  mess::MessSystem b = a;
  mess::MinimiserOptions mo;
  mo.force_tolerance = 1e-10;
  ASSERT_TRUE(mess::minimise(a, mo).converged);
  const Eigen::Vector3d shift = a.positions().col(top[0]) - l.positions.col(top[0]);
  EXPECT_GT(shift.x(), 0.0);
  for (const int n : top) {
    EXPECT_LT((a.positions().col(n) - l.positions.col(n) - shift).norm(), 1e-15 * l.element_length);
  }
  mess::LeapfrogOptions lo;
  lo.steps_per_round = 1000;
  lo.tolerance = 1e-9;
  lo.rigid_group_rule = mess::RigidGroupRule::total_force;
  ASSERT_TRUE(mess::relax_leapfrog(b, lo).converged);
  EXPECT_LT((a.positions() - b.positions()).cwiseAbs().maxCoeff(), 1e-6 * shift.x());
}

TEST(MessSolvers, IndependentOfThreadCount) {
  // Large enough for the parallel loops (> detail::kParallelMinimum springs).
  const lat::Lattice l =
      small_lattice(mess::model_profile("physical"), {15, 15, 19}, {{7, 7, 5}, {7, 7, 13}});
  ASSERT_GT(l.node_count(), 4096);
  const auto run = [&](int threads) {
    omp_set_num_threads(threads);
    mess::MessSystem sys =
        mess::MessSystem::make(l, tesla(0.0, 0.0, 0.1), mess::model_profile("physical"));
    sys.set_constraints(all_faces_held(l, l.positions));
    mess::MinimiserOptions opt;
    opt.force_tolerance = 1e-6;
    (void)mess::minimise(sys, opt);
    return sys.positions();
  };
  const int saved = omp_get_max_threads();
  const Eigen::Matrix3Xd one = run(1);
  const Eigen::Matrix3Xd two = run(2);
  const Eigen::Matrix3Xd three = run(3);
  omp_set_num_threads(saved);
  EXPECT_TRUE(one == two);
  EXPECT_TRUE(one == three);
}
