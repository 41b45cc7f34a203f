// Tests of the elastic terms of the 3D model (eqs. 4.62-4.69): gradients against finite
// differences on a randomly perturbed small lattice with a particle, the seed profile's 4x
// volume force, the parallel evaluator against the serial formulas, and independence of the
// thread count.

#include "mresim/mess/terms/elastic_terms.hpp"

#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>

#include "../support/mess_test_support.hpp"

namespace mess = mresim::mess;
namespace lat = mresim::lattice;
using mess::testing::all_coordinates;
using mess::testing::central_differences;
using mess::testing::perturbed;
using mess::testing::relative_error;
using mess::testing::small_lattice;

namespace {

// 5 x 5 x 6 cells with one n_d = 1 particle (3 voxels across) in the middle.
lat::Lattice block_with_particle(const mess::ModelProfile& profile) {
  return small_lattice(profile, {5, 5, 6}, {{2, 2, 2}});
}

}  // namespace

TEST(MessElastic, SpringGradientMatchesFiniteDifferences) {
  const lat::Lattice l = block_with_particle(mess::model_profile("physical"));
  const double le = l.element_length;
  const Eigen::Matrix3Xd x = perturbed(l.positions, 0.1 * le);
  Eigen::Matrix3Xd g = Eigen::Matrix3Xd::Zero(3, x.cols());
  mess::add_spring_gradient(l.springs, x, g);
  const auto coords = all_coordinates(x);
  const auto fd = central_differences(
      [&](const Eigen::Matrix3Xd& y) { return mess::spring_energy(l.springs, y); }, x, coords,
      1e-6 * le);
  EXPECT_LT(relative_error(g, coords, fd), 1e-7);
  // Newton's third law: no net force.
  EXPECT_LT(g.rowwise().sum().norm(), 1e-12 * g.norm());
}

TEST(MessElastic, VolumeGradientMatchesFiniteDifferences) {
  const lat::Lattice l = block_with_particle(mess::model_profile("physical"));
  const double le = l.element_length;
  const Eigen::Matrix3Xd x = perturbed(l.positions, 0.1 * le, 11);
  const double kappa = l.polymer.kappa;
  Eigen::Matrix3Xd g = Eigen::Matrix3Xd::Zero(3, x.cols());
  mess::add_volume_gradient(l.elements, kappa, le, x, g);
  const auto coords = all_coordinates(x);
  const auto fd = central_differences(
      [&](const Eigen::Matrix3Xd& y) { return mess::volume_energy(l.elements, kappa, le, y); }, x,
      coords, 1e-6 * le);
  EXPECT_LT(relative_error(g, coords, fd), 1e-7);
}

// Eq. 4.64 is a density: one cell compressed uniformly by s has energy 0.5 kappa l_e^3
// ((1 - s)^3 - 1)^2.
TEST(MessElastic, VolumeEnergyCarriesTheCellVolume) {
  const lat::Lattice l = small_lattice(mess::model_profile("physical"), {1, 1, 1});
  const double s = 0.02;
  const Eigen::Matrix3Xd x = (1.0 - s) * l.positions;
  const double dv = std::pow(1.0 - s, 3) - 1.0;
  const double expected = 0.5 * l.polymer.kappa * std::pow(l.element_length, 3) * dv * dv;
  EXPECT_NEAR(mess::volume_energy(l.elements, l.polymer.kappa, l.element_length, x), expected,
              1e-13 * expected);
}

// The seed profile's forces are 4x the volume term's gradient while its energy is the same
// (docs/original-code.md#volume-elements); the physical profile's are the exact gradient.
TEST(MessElastic, SeedVolumeForceIsFourTimesTheGradient) {
  for (const std::string_view name : {"physical", "seed"}) {
    const mess::ModelProfile& profile = mess::model_profile(name);
    const lat::Lattice l = block_with_particle(profile);
    const double le = l.element_length;
    const Eigen::Matrix3Xd x = perturbed(l.positions, 0.05 * le, 3);
    const mess::ElasticTerms terms(l, profile.system_settings().elastic);
    Eigen::Matrix3Xd g;
    const mess::ElasticEnergies e = terms.evaluate(l, x, &g);
    EXPECT_DOUBLE_EQ(e.volume, mess::volume_energy(l.elements, l.polymer.kappa, le, x));
    Eigen::Matrix3Xd springs = Eigen::Matrix3Xd::Zero(3, x.cols());
    mess::add_spring_gradient(l.springs, x, springs);
    Eigen::Matrix3Xd volume = Eigen::Matrix3Xd::Zero(3, x.cols());
    mess::add_volume_gradient(l.elements, l.polymer.kappa, le, x, volume);
    const double factor = profile.volume_force_factor;
    EXPECT_LT((g - springs - factor * volume).norm(), 1e-11 * g.norm()) << profile.name;
  }
}

TEST(MessElastic, EvaluatorMatchesSerialFormulas) {
  const lat::Lattice l = block_with_particle(mess::model_profile("physical"));
  const Eigen::Matrix3Xd x = perturbed(l.positions, 0.1 * l.element_length, 5);
  const mess::ElasticTerms terms(l, mess::ElasticTermSettings{});
  Eigen::Matrix3Xd g;
  const mess::ElasticEnergies e = terms.evaluate(l, x, &g);
  const double springs = mess::spring_energy(l.springs, x);
  const double volume = mess::volume_energy(l.elements, l.polymer.kappa, l.element_length, x);
  EXPECT_NEAR(e.springs, springs, 1e-13 * springs);
  EXPECT_NEAR(e.volume, volume, 1e-13 * volume);
  Eigen::Matrix3Xd ref = Eigen::Matrix3Xd::Zero(3, x.cols());
  mess::add_spring_gradient(l.springs, x, ref);
  mess::add_volume_gradient(l.elements, l.polymer.kappa, l.element_length, x, ref);
  EXPECT_LT((g - ref).norm(), 1e-12 * ref.norm());
  // Energies without a gradient are the same.
  const mess::ElasticEnergies e2 = terms.evaluate(l, x, nullptr);
  EXPECT_EQ(e2.springs, e.springs);
  EXPECT_EQ(e2.volume, e.volume);
}

TEST(MessElastic, IndependentOfThreadCount) {
  // Big enough for the parallel loops (detail::kParallelMinimum) and many summation blocks.
  const lat::Lattice l =
      small_lattice(mess::model_profile("seed"), {16, 16, 24}, {{8, 8, 6}, {8, 8, 16}});
  ASSERT_GT(static_cast<std::int64_t>(l.springs.size()), 4 * 16384);
  const Eigen::Matrix3Xd x = perturbed(l.positions, 0.1 * l.element_length, 9);
  const mess::ElasticTerms terms(l, mess::model_profile("seed").system_settings().elastic);
  const int saved = omp_get_max_threads();
  omp_set_num_threads(1);
  Eigen::Matrix3Xd g1;
  const mess::ElasticEnergies e1 = terms.evaluate(l, x, &g1);
  for (const int threads : {2, 3, 8}) {
    omp_set_num_threads(threads);
    Eigen::Matrix3Xd g;
    const mess::ElasticEnergies e = terms.evaluate(l, x, &g);
    EXPECT_EQ(e.springs, e1.springs) << threads;
    EXPECT_EQ(e.volume, e1.volume) << threads;
    EXPECT_TRUE(g == g1) << threads;
  }
  omp_set_num_threads(saved);
}
