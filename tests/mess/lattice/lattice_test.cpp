#include "mresim/mess/lattice/lattice.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <numbers>

#include "../../support/dissertation_values.hpp"
#include "affine_energy.hpp"

namespace mresim::lattice {
namespace {

using mresim::testing::kE;

// Claim D1, Phi = 3 %: 52,200 nodes (30 x 30 x 58), 47,937 cells, assembled.
TEST(LatticeBuild, PhiThreePercentTwoParticleSystem) {
  LatticeSpec spec;
  spec.placement = RegularPlacement{0.03, {1, 1, 2}};
  const Lattice lat = build_lattice(spec);
  EXPECT_EQ(lat.shape.nodes, (std::array<int, 3>{30, 30, 58}));
  EXPECT_EQ(lat.node_count(), 52200);
  EXPECT_EQ(lat.cell_count(), 47937);
  EXPECT_EQ(lat.elements.size(), 47937u);
  EXPECT_EQ(lat.positions.cols(), 52200);
  EXPECT_EQ(lat.masses.size(), 52200);
  EXPECT_EQ(lat.node_types.size(), 52200u);
  EXPECT_EQ(static_cast<std::int64_t>(lat.springs.size()),
            closed_form_spring_counts(lat.shape).total());
  ASSERT_EQ(lat.particle_count(), 2u);
  const double l_e = lat.element_length;
  EXPECT_NEAR((lat.box_lengths() - Eigen::Vector3d(29, 29, 57) * l_e).norm(), 0.0, 1e-18);
  // Centres: cell centres 14.5 and 42.5 l_e along z (S = 28 voxels = 7.636 um).
  EXPECT_NEAR((lat.particle_centres[0] - Eigen::Vector3d(14.5, 14.5, 14.5) * l_e).norm(), 0.0,
              1e-18);
  EXPECT_NEAR((lat.particle_centres[1] - Eigen::Vector3d(14.5, 14.5, 42.5) * l_e).norm(), 0.0,
              1e-18);
  // The mean of each particle's first 8 nodes is its centre (the original's dynamics centre).
  for (std::size_t p = 0; p < 2; ++p) {
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (int k = 0; k < 8; ++k) mean += lat.positions.col(lat.particle_nodes[p][k]) / 8.0;
    EXPECT_NEAR((mean - lat.particle_centres[p]).norm(), 0.0, 1e-18);
    for (const auto n : lat.particle_nodes[p]) {
      EXPECT_EQ(lat.node_types[n], node_type::kParticle);
      EXPECT_EQ(lat.particle_of_node[n], static_cast<std::int32_t>(p));
    }
  }
  // Node positions follow the numbering.
  const int n = lat.shape.node_index(3, 7, 11);
  EXPECT_NEAR((lat.positions.col(n) - Eigen::Vector3d(3, 7, 11) * l_e).norm(), 0.0, 1e-18);
  EXPECT_EQ(lat.node_types[lat.shape.node_index(0, 0, 0)], 19);
  // Reported volume fraction 2 V_p / (L_x L_y L_z) and the masses.
  const double vp = sphere_volume(1.5e-6);
  EXPECT_NEAR(lat.volume_fraction(), 2 * vp / lat.box_lengths().prod(), 1e-15);
  EXPECT_NEAR(lat.volume_fraction(), 0.02908, 0.00001);  // the rounded box is a bit larger
  const double cell = std::pow(l_e, 3);
  EXPECT_NEAR(lat.masses.sum(), kPolymerDensity * (47937 - 2 * 1064) * cell + kIronDensity * 2 * vp,
              1e-12 * lat.masses.sum());
  // Stiffness: physical profile by default.
  EXPECT_NEAR(lattice_moduli(lat.polymer, l_e).shear_modulus, kE / (2 * 1.47), 1e-9);
  EXPECT_NEAR(lat.particle_springs.edge / lat.polymer.springs.edge, 1e4, 1e-8);
}

// Claim D1, the remaining two-particle volume fractions (sizes only are built here).
TEST(LatticeBuild, OtherVolumeFractions) {
  const struct {
    double phi;
    std::int64_t nodes, cells;
  } cases[] = {
      {0.04, 38637, 35152}, {0.05, 30625, 27648}, {0.06, 26496, 23805}, {0.07, 23276, 20812}};
  for (const auto& c : cases) {
    LatticeSpec spec;
    spec.placement = RegularPlacement{c.phi, {1, 1, 2}};
    const Lattice lat = build_lattice(spec);
    EXPECT_EQ(lat.node_count(), c.nodes) << c.phi;
    EXPECT_EQ(lat.cell_count(), c.cells) << c.phi;
    EXPECT_NEAR(lat.volume_fraction(), c.phi, 0.1 * c.phi) << c.phi;
  }
}

Lattice particle_free_block(ShearModulusRule rule, double nu, std::array<int, 3> cells) {
  LatticeSpec spec;
  spec.shear_modulus_rule = rule;
  spec.poisson_ratio = nu;
  const double l_e = element_length(spec.particle_radius, spec.discretization_order);
  spec.placement = ByHandPlacement{
      {Eigen::Vector3d(cells[0] * l_e, cells[1] * l_e, cells[2] * l_e), BoxRounding::nearest}, {}};
  return build_lattice(spec);
}

// A particle-free block of the physical profile, deformed affinely, has exactly the user's
// moduli, boundary springs included: the half and quarter weights make the block's energy
// exactly (cells) x (one periodic cell's energy). The seed profile shears with 0.4 E.
TEST(LatticeBuild, ParticleFreeBlockHasTheUsersModuli) {
  for (const double nu : {0.47, 0.3, 0.1, -0.4}) {
    const Lattice lat =
        particle_free_block(ShearModulusRule::from_youngs_and_poisson, nu, {3, 4, 5});
    ASSERT_EQ(lat.node_count(), 4 * 5 * 6);
    const auto w = [&](const Eigen::Matrix3d& f) {
      return testing::lattice_energy_density(lat, f);
    };
    const auto m = testing::measure_moduli(w);
    const double tol = 1e-6 * kE / (1 - 2 * nu);
    EXPECT_NEAR(m.shear, kE / (2 * (1 + nu)), tol) << nu;
    EXPECT_NEAR(m.bulk, kE / (3 * (1 - 2 * nu)), tol) << nu;
    EXPECT_NEAR(m.youngs, kE, tol) << nu;
    EXPECT_NEAR(m.poisson, nu, 1e-6) << nu;
    // Also at finite strain: block energy = one periodic cell's energy, per volume.
    Eigen::Matrix3d f;
    f << 1.05, 0.1, -0.02, 0.0, 0.97, 0.04, 0.03, -0.01, 1.1;
    EXPECT_NEAR(w(f), testing::cell_energy_density(lat.polymer, lat.element_length, f),
                1e-10 * w(f));
  }
  const Lattice seed = particle_free_block(ShearModulusRule::two_fifths_youngs, 0.47, {3, 4, 5});
  const auto m = testing::measure_moduli(
      [&](const Eigen::Matrix3d& f) { return testing::lattice_energy_density(seed, f); });
  EXPECT_NEAR(m.shear, 3600.0, 1e-6 * kE);
  EXPECT_NEAR(m.youngs, lattice_moduli(seed.polymer, seed.element_length).youngs_modulus,
              1e-5 * kE);
}

// Smallest non-rigid eigenvalue of the energy Hessian at rest of a free particle-free block
// (springs + 0.5 kappa V0 (V/V0 - 1)^2 per cell), relative to the edge constant.
double smallest_elastic_eigenvalue(const Lattice& lat) {
  const int dof = 3 * static_cast<int>(lat.node_count());
  Eigen::MatrixXd h = Eigen::MatrixXd::Zero(dof, dof);
  const SpringSet& s = lat.springs;
  for (std::size_t i = 0; i < s.size(); ++i) {
    const Eigen::Vector3d d = lat.positions.col(s.second(i)) - lat.positions.col(s.first[i]);
    const Eigen::Matrix3d b = s.stiffness(i) * d * d.transpose() / d.squaredNorm();
    const int a = 3 * s.first[i], c = 3 * s.second(i);
    h.block<3, 3>(a, a) += b;
    h.block<3, 3>(c, c) += b;
    h.block<3, 3>(a, c) -= b;
    h.block<3, 3>(c, a) -= b;
  }
  const double v0 = std::pow(lat.element_length, 3);
  for (const auto& e : lat.elements) {
    CellVertices x, g;
    for (int k = 0; k < 8; ++k) x[k] = lat.positions.col(e[k]);
    cell_volume_and_gradient(x, g);
    for (int p = 0; p < 8; ++p) {
      for (int q = 0; q < 8; ++q) {
        h.block<3, 3>(3 * e[p], 3 * e[q]) += lat.polymer.kappa / v0 * g[p] * g[q].transpose();
      }
    }
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(h, Eigen::EigenvaluesOnly);
  Eigen::VectorXd ev = eig.eigenvalues() / lat.polymer.springs.edge;
  // Six rigid-body modes have zero eigenvalue; return the smallest of the rest by magnitude
  // ordering: if anything is clearly negative, that is the answer.
  if (ev[0] < -1e-9) return ev[0];
  return ev[6];
}

// nu < 1/4 gives kappa < 0 (an energy gain per unit volume change). The physical profile's
// lattice stays stable (positive-definite Hessian apart from rigid modes) down to nu -> -1;
// the seed profile's has a negative bulk modulus below nu = -0.1124 and is unstable there.
TEST(LatticeBuild, StabilityBelowOneQuarter) {
  for (const double nu : {0.47, 0.25, 0.0, -0.5, -0.9, -0.99}) {
    const Lattice lat =
        particle_free_block(ShearModulusRule::from_youngs_and_poisson, nu, {3, 3, 3});
    const double lambda = smallest_elastic_eigenvalue(lat);
    RecordProperty("physical_nu_" + std::to_string(nu), std::to_string(lambda));
    EXPECT_GT(lambda, 1e-6) << "physical, nu = " << nu;
  }
  for (const double nu : {0.0, -0.1}) {
    EXPECT_GT(smallest_elastic_eigenvalue(
                  particle_free_block(ShearModulusRule::two_fifths_youngs, nu, {3, 3, 3})),
              1e-6)
        << "seed, nu = " << nu;
  }
  for (const double nu : {-0.13, -0.5}) {
    EXPECT_LT(smallest_elastic_eigenvalue(
                  particle_free_block(ShearModulusRule::two_fifths_youngs, nu, {3, 3, 3})),
              -1e-6)
        << "seed, nu = " << nu;
  }
}

TEST(LatticeBuild, InvalidSpecsThrow) {
  LatticeSpec spec;
  spec.placement = RegularPlacement{0.03, {1, 1, 2}};
  spec.poisson_ratio = 0.5;
  EXPECT_THROW(build_lattice(spec), std::invalid_argument);
  spec.poisson_ratio = 0.47;
  spec.discretization_order = 0;
  EXPECT_THROW(build_lattice(spec), std::invalid_argument);
  spec.discretization_order = 5;
  spec.placement = RegularPlacement{0.5, {1, 1, 2}};  // particles do not fit
  EXPECT_THROW(build_lattice(spec), std::invalid_argument);
}

}  // namespace
}  // namespace mresim::lattice
