// Tests of the assembled energy of the 3D system: the gradient of the total energy against
// finite differences at fixed M and with M re-solved at every displaced position (envelope
// theorem), the even spreading of the particle forces, the energy breakdown, the magnetization
// update rules, and the seed profile's centre and 4x volume force.

#include "mresim/mess/system/system_energy.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "../support/mess_test_support.hpp"

namespace mess = mresim::mess;
namespace lat = mresim::lattice;
namespace mm = mresim::magnetism;
using mess::testing::central_differences;
using mess::testing::perturbed;
using mess::testing::relative_error;
using mess::testing::small_lattice;
using mess::testing::tesla;

namespace {

// Two n_d = 1 particles (3 voxels across) along z, one polymer layer apart... plus a lateral
// offset so that nothing is symmetric: 6 x 6 x 10 cells.
mess::MessSystem two_particle_system(const mess::ModelProfile& profile, const Eigen::Vector3d& H) {
  return mess::MessSystem::make(small_lattice(profile, {6, 6, 10}, {{2, 2, 2}, {3, 3, 6}}), H,
                                profile);
}

// Coordinates to difference: every coordinate of both particles' nodes and of a sample of
// polymer nodes.
std::vector<Eigen::Index> sample_coordinates(const lat::Lattice& l) {
  std::vector<Eigen::Index> k;
  for (const auto& nodes : l.particle_nodes) {
    for (const std::int32_t n : nodes) {
      for (int a = 0; a < 3; ++a) k.push_back(3 * n + a);
    }
  }
  for (Eigen::Index n = 0; n < l.node_count(); n += 17) {
    for (int a = 0; a < 3; ++a) k.push_back(3 * n + a);
  }
  return k;
}

Eigen::Matrix3Xd two_particle_magnetizations(double Ms) {
  Eigen::Matrix3Xd M(3, 2);
  M.col(0) = Ms * Eigen::Vector3d(0.2, -0.1, 0.6);
  M.col(1) = Ms * Eigen::Vector3d(-0.3, 0.25, 0.5);
  return M;
}

}  // namespace

TEST(MessSystem, GradientMatchesFiniteDifferencesAtFixedM) {
  mess::MessSystem sys =
      two_particle_system(mess::model_profile("physical"), tesla(0.03, 0.0, 0.08));
  sys.settings().magnetization_update = mess::MagnetizationUpdate::manual;
  sys.set_magnetizations(two_particle_magnetizations(sys.model().particles.Ms));
  const double le = sys.length_scale();
  // Particles pressed towards contact so that WCA acts too.
  Eigen::Matrix3Xd x = perturbed(sys.lattice().positions, 0.05 * le, 21);
  for (const std::int32_t n : sys.lattice().particle_nodes[1]) x(2, n) -= 1.2 * le;
  sys.set_positions(x);
  Eigen::Matrix3Xd g;
  const mess::Evaluation ev = sys.evaluate(&g);
  EXPECT_GT(ev.energies["wca"], 0.0);
  EXPECT_NE(ev.energies["dipole"], 0.0);
  EXPECT_DOUBLE_EQ(ev.potential, ev.energies.total());  // physical: factor 1
  const auto coords = sample_coordinates(sys.lattice());
  const auto fd = central_differences(
      [&](const Eigen::Matrix3Xd& y) {
        sys.set_positions(y);
        return sys.evaluate(nullptr).potential;
      },
      x, coords, 1e-6 * le);
  EXPECT_LT(relative_error(g, coords, fd), 2e-7);
  // The magnetic part is shared equally: per particle its nodes carry dE/dc / n_p each.
  sys.set_positions(x);
  const Eigen::Matrix3Xd gc = sys.centre_gradient();
  Eigen::Matrix3Xd g_elastic;
  mess::ElasticTerms(sys.lattice(), sys.settings().elastic).evaluate(sys.lattice(), x, &g_elastic);
  for (std::size_t p = 0; p < 2; ++p) {
    const auto& nodes = sys.lattice().particle_nodes[p];
    for (const std::int32_t n : nodes) {
      EXPECT_TRUE((g.col(n) - g_elastic.col(n))
                      .isApprox(gc.col(static_cast<Eigen::Index>(p)) / nodes.size(), 1e-9));
    }
  }
}

// With M re-solved (to a tight tolerance, from the same history) at every displaced position,
// the derivative of the total energy is still the gradient at fixed M.
TEST(MessSystem, EnvelopeTheoremWithResolvedMagnetization) {
  mess::MessSystem sys =
      two_particle_system(mess::model_profile("physical"), tesla(0.02, 0.0, 0.05));
  sys.settings().magnetization.atol = 1e-13;
  sys.settings().magnetization.rtol = 1e-13;
  sys.settings().magnetization.max_fixed_point_iterations = 500;
  sys.settings().magnetization_update = mess::MagnetizationUpdate::every_evaluation;
  const double le = sys.length_scale();
  Eigen::Matrix3Xd x = perturbed(sys.lattice().positions, 0.05 * le, 4);
  for (const std::int32_t n : sys.lattice().particle_nodes[1]) x(2, n) -= 0.8 * le;
  sys.set_positions(x);
  Eigen::Matrix3Xd g;
  (void)sys.evaluate(&g);
  ASSERT_TRUE(sys.magnetization_stats().last.converged);
  const Eigen::Matrix3Xd M0 = sys.magnetizations();
  EXPECT_GT(M0.col(0).norm(), 0.1 * sys.model().particles.Ms);
  const auto coords = sample_coordinates(sys.lattice());
  const auto fd = central_differences(
      [&](const Eigen::Matrix3Xd& y) {
        sys.set_positions(y);
        sys.set_magnetizations(M0);  // same branch, same start
        return sys.evaluate(nullptr).potential;
      },
      x, coords, 1e-6 * le);
  EXPECT_LT(relative_error(g, coords, fd), 1e-6);
  // The magnetization does change with the particle positions (the test is not trivial).
  Eigen::Matrix3Xd y = x;
  for (const std::int32_t n : sys.lattice().particle_nodes[1]) y(0, n) += 1e-3 * le;
  sys.set_positions(y);
  sys.set_magnetizations(M0);
  (void)sys.evaluate(nullptr);
  EXPECT_GT((sys.magnetizations() - M0).norm(), 1e-6 * M0.norm());
}

TEST(MessSystem, EnergyBreakdownAndLinearizedSelfEnergy) {
  mess::MessSystem sys = two_particle_system(mess::model_profile("physical"), tesla(0.0, 0.0, 0.1));
  const mess::Evaluation ev = sys.evaluate(nullptr);
  const mess::MessEnergies& e = ev.energies;
  EXPECT_EQ(sys.magnetization_stats().solves, 1);
  EXPECT_TRUE(sys.magnetization_stats().last.converged);
  // Undeformed lattice: no elastic energy.
  EXPECT_LT(e["springs"], 1e-30);
  EXPECT_LT(e["volume"], 1e-30);
  // Magnetic terms as the magnetism module computes them at the all-nodes centres.
  const Eigen::Matrix3Xd c = sys.particle_centres();
  const mm::MagneticEnergyBreakdown b = mm::magnetic_energies(sys.model(), c, sys.magnetizations());
  EXPECT_DOUBLE_EQ(e["zeeman"], b.zeeman);
  EXPECT_DOUBLE_EQ(e["dipole"], b.dipole);
  EXPECT_DOUBLE_EQ(e["self"], b.self);
  mm::MagneticModel lin = sys.model();
  lin.self_energy = mm::SelfEnergyForm::linearized;
  EXPECT_DOUBLE_EQ(e["self_linearized"], mm::self_energy(lin, c, sys.magnetizations()));
  EXPECT_NE(e["self_linearized"], e["self"]);
  EXPECT_DOUBLE_EQ(e.total(),
                   e["springs"] + e["volume"] + e["zeeman"] + e["dipole"] + e["self"] + e["wca"]);
  // Centres of the undeformed lattice are the voxel centres, under both rules.
  for (Eigen::Index p = 0; p < 2; ++p) {
    const Eigen::Vector3d expected = sys.lattice().particle_centres[static_cast<std::size_t>(p)];
    EXPECT_TRUE(c.col(p).isApprox(expected, 1e-14));
    EXPECT_TRUE(
        sys.particle_centres(mess::CentreRule::centre_voxel).col(p).isApprox(expected, 1e-14));
    EXPECT_TRUE(sys.particle_bounding_box_centres().col(p).isApprox(expected, 1e-14));
  }
}

TEST(MessSystem, MagnetizationUpdateRules) {
  mess::MessSystem sys =
      two_particle_system(mess::model_profile("physical"), tesla(0.0, 0.0, 0.05));
  const double le = sys.length_scale();
  sys.settings().magnetization_update = mess::MagnetizationUpdate::on_displacement;
  sys.settings().resolve_distance = 0.01;
  (void)sys.evaluate(nullptr);
  EXPECT_EQ(sys.magnetization_stats().solves, 1);
  Eigen::Matrix3Xd x = sys.positions();
  for (const std::int32_t n : sys.lattice().particle_nodes[0]) x(2, n) += 0.005 * le;
  sys.set_positions(x);
  (void)sys.evaluate(nullptr);
  EXPECT_EQ(sys.magnetization_stats().solves, 1);  // moved less than 0.01 l_e
  for (const std::int32_t n : sys.lattice().particle_nodes[0]) x(2, n) += 0.01 * le;
  sys.set_positions(x);
  (void)sys.evaluate(nullptr);
  EXPECT_EQ(sys.magnetization_stats().solves, 2);
  sys.set_applied_field(tesla(0.0, 0.0, 0.06));  // a new field always re-solves
  (void)sys.evaluate(nullptr);
  EXPECT_EQ(sys.magnetization_stats().solves, 3);
  sys.settings().magnetization_update = mess::MagnetizationUpdate::manual;
  sys.set_applied_field(tesla(0.0, 0.0, 0.07));
  (void)sys.evaluate(nullptr);
  EXPECT_EQ(sys.magnetization_stats().solves, 3);
  sys.settings().magnetization_update = mess::MagnetizationUpdate::every_evaluation;
  (void)sys.evaluate(nullptr);
  (void)sys.evaluate(nullptr);
  EXPECT_EQ(sys.magnetization_stats().solves, 5);
  EXPECT_EQ(sys.magnetization_stats().unconverged, 0);
}

// Seed profile: centre = mean of the centre voxel's corners, force spread evenly (not that
// centre's exact gradient), volume forces 4x; the potential carries 4 x volume.
TEST(MessSystem, SeedProfileCentresAndPotential) {
  mess::MessSystem sys = two_particle_system(mess::model_profile("seed"), tesla(0.0, 0.0, 0.1));
  EXPECT_EQ(sys.settings().centre_rule, mess::CentreRule::centre_voxel);
  EXPECT_EQ(sys.settings().elastic.volume_force_factor, 4.0);
  EXPECT_DOUBLE_EQ(sys.model().wca.e_max,
                   mm::WcaParameters::from_radius(sys.lattice().particle_radius, 1.9e6).e_max);
  const double le = sys.length_scale();
  Eigen::Matrix3Xd x = perturbed(sys.lattice().positions, 0.02 * le, 8);
  sys.set_positions(x);
  Eigen::Matrix3Xd g;
  const mess::Evaluation ev = sys.evaluate(&g);
  EXPECT_NEAR(ev.potential, ev.energies.total() + 3.0 * ev.energies["volume"],
              1e-12 * ev.magnitude);
  const auto& nodes = sys.lattice().particle_nodes[0];
  Eigen::Vector3d c8 = Eigen::Vector3d::Zero();
  for (int k = 0; k < 8; ++k) c8 += x.col(nodes[static_cast<std::size_t>(k)]);
  EXPECT_TRUE(sys.particle_centres().col(0).isApprox(c8 / 8.0, 1e-15));
  // Spread evenly over all nodes of the particle.
  Eigen::Matrix3Xd g_elastic;
  mess::ElasticTerms(sys.lattice(), sys.settings().elastic).evaluate(sys.lattice(), x, &g_elastic);
  const Eigen::Matrix3Xd gc = sys.centre_gradient();
  for (const std::int32_t n : nodes) {
    EXPECT_TRUE((g.col(n) - g_elastic.col(n)).isApprox(gc.col(0) / nodes.size(), 1e-9));
  }
}

TEST(MessSystem, ConstraintsAndAppliedForces) {
  mess::MessSystem sys =
      two_particle_system(mess::model_profile("physical"), Eigen::Vector3d::Zero());
  const lat::Lattice& l = sys.lattice();
  mess::BoundaryConstraints c = mess::BoundaryConstraints::none(l.node_count());
  Eigen::Matrix3Xd target = l.positions;
  target.row(0).array() += 0.1 * sys.length_scale();
  c.fix_face(l.shape, lat::Face::bottom, target);
  sys.set_constraints(c);
  for (const int n : lat::face_nodes(l.shape, lat::Face::bottom)) {
    EXPECT_EQ(sys.positions().col(n), target.col(n));
  }
  // A node in a rigid group may not also be held.
  mess::BoundaryConstraints bad = c;
  bad.add_rigid_group({static_cast<std::int32_t>(lat::face_nodes(l.shape, lat::Face::bottom)[0])});
  EXPECT_THROW(sys.set_constraints(bad), std::invalid_argument);
  // Load: -sum f.(x - x0), gradient -f.
  Eigen::Matrix3Xd f = Eigen::Matrix3Xd::Zero(3, l.node_count());
  f(2, 5) = 1e-9;
  sys.set_applied_forces(f);
  Eigen::Matrix3Xd x = sys.positions();
  x(2, 5) += 0.2 * sys.length_scale();
  sys.set_positions(x);
  Eigen::Matrix3Xd g;
  const mess::Evaluation ev = sys.evaluate(&g);
  EXPECT_NEAR(ev.energies["load"], -1e-9 * 0.2 * sys.length_scale(), 1e-25);
  Eigen::Matrix3Xd g_elastic;
  mess::ElasticTerms(l, sys.settings().elastic).evaluate(l, x, &g_elastic);
  EXPECT_NEAR(g(2, 5) - g_elastic(2, 5), -1e-9, 1e-20);
}
