// Tests of the distributed elastic terms (distributed/distributed_elastic.hpp) against the
// single-process kernels (ElasticTerms): the gradient bitwise, the energies and their rounding
// scales to 1e-13 relative, on lattices with particles (seed and physical profiles), a thin
// one (two node layers along z, where two spring offsets share an index step) and one big
// enough for the threaded loops. Every test splits the grid along each axis in turn and lets
// PETSc choose, on whatever processes MPI_COMM_WORLD has: one when ctest runs the suite, two
// in `mess_distributed_two_ranks` (`mpirun -np 2`, CMakeLists.txt), where the ghost layers and
// the sum over processes are exercised.
//
// Every process runs the same checks in the same order (the calls are collective), and a
// failure on any process fails the test on all of them, so that no process waits for another
// that gave up.

#include "mresim/mess/distributed/distributed_elastic.hpp"

#include <gtest/gtest.h>
#include <omp.h>

#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "../support/mess_test_support.hpp"
#include "mpi_test_support.hpp"
#include "mresim/mess/profile/model_profile.hpp"
#include "mresim/mess/solvers/amg_preconditioner.hpp"
#include "mresim/mess/terms/elastic_terms.hpp"

namespace mess = mresim::mess;
namespace lat = mresim::lattice;
using mess::testing::everywhere;
using mess::testing::perturbed;
using mess::testing::relative_difference;
using mess::testing::small_lattice;
using mess::testing::world_size;

namespace {

// The splits to try: all processes along x, then y, then z, then PETSc's choice.
std::vector<std::array<int, 3>> splits() {
  const int p = world_size();
  return {{p, 1, 1}, {1, p, 1}, {1, 1, p}, {0, 0, 0}};
}

// Distributed against single-process, for every split; `label` names the case in failures.
void expect_matches_single_process(const lat::Lattice& l, double volume_force_factor,
                                   const std::string& label) {
  // The same strained state on every process (same seed).
  const Eigen::Matrix3Xd x = perturbed(l.positions, 0.1 * l.element_length, 11);
  mess::ElasticTermSettings settings;
  settings.volume_force_factor = volume_force_factor;
  const mess::ElasticTerms serial(l, settings);
  Eigen::Matrix3Xd expected(3, x.cols());
  const mess::ElasticEnergies e = serial.evaluate(l, x, &expected);

  for (const std::array<int, 3>& split : splits()) {
    // A split with more processes than nodes along an axis is not possible (RefusesMismatched
    // Input checks the error); skip it.
    if (!mess::LatticeDecomposition::can_split(l.shape, world_size(), split)) continue;
    SCOPED_TRACE(label + ", processes along x, y, z: " + std::to_string(split[0]) + ", " +
                 std::to_string(split[1]) + ", " + std::to_string(split[2]));
    const mess::LatticeDecomposition decomposition(l.shape, MPI_COMM_WORLD, split);
    const mess::DistributedElastic distributed(l, decomposition, volume_force_factor);
    Vec positions = decomposition.create_global_vector();
    Vec gradient = decomposition.create_global_vector();
    decomposition.scatter(x, positions);
    const mess::ElasticEnergies d = distributed.evaluate(positions, gradient);
    const Eigen::Matrix3Xd got = decomposition.gather(gradient);
    // Energy only (no gradient): the same energies.
    const mess::ElasticEnergies energy_only = distributed.evaluate(positions, nullptr);
    (void)VecDestroy(&positions);
    (void)VecDestroy(&gradient);

    const bool same_gradient = got == expected;
    EXPECT_TRUE(everywhere(same_gradient))
        << "largest gradient difference " << (got - expected).cwiseAbs().maxCoeff() << " of "
        << expected.cwiseAbs().maxCoeff();
    const std::array<double, 4> differences = {
        relative_difference(d.springs, e.springs), relative_difference(d.volume, e.volume),
        relative_difference(d.springs_rounding, e.springs_rounding),
        relative_difference(d.volume_rounding, e.volume_rounding)};
    for (const double difference : differences) {
      EXPECT_TRUE(everywhere(difference < 1e-13)) << "relative energy difference " << difference;
    }
    EXPECT_EQ(energy_only.springs, d.springs);
    EXPECT_EQ(energy_only.volume, d.volume);
  }
}

}  // namespace

TEST(DistributedElastic, GradientIsBitwiseTheSingleProcessOneWithParticles) {
  expect_matches_single_process(
      small_lattice(mess::model_profile("physical"), {6, 7, 9}, {{2, 3, 2}, {3, 3, 6}}), 1.0,
      "physical profile, two particles");
  // The seed profile: any_particle springs and the volume forces 4x the volume gradient.
  const mess::ModelProfile seed = mess::model_profile("seed");
  expect_matches_single_process(small_lattice(seed, {6, 7, 9}, {{2, 3, 2}, {3, 3, 6}}),
                                seed.system_settings().elastic.volume_force_factor,
                                "seed profile, two particles");
}

TEST(DistributedElastic, GradientIsBitwiseTheSingleProcessOneOnThinAndSmallGrids) {
  const mess::ModelProfile physical = mess::model_profile("physical");
  for (const std::array<int, 3> cells :
       {std::array<int, 3>{1, 1, 1}, std::array<int, 3>{5, 4, 1}, std::array<int, 3>{1, 6, 3}}) {
    expect_matches_single_process(small_lattice(physical, cells), 1.0,
                                  "cells " + std::to_string(cells[0]) + " x " +
                                      std::to_string(cells[1]) + " x " + std::to_string(cells[2]));
  }
}

TEST(DistributedElastic, GradientIsBitwiseTheSingleProcessOneOnAnyThreadCount) {
  // 30 x 30 x 30 nodes: the kernels' threaded loops run in parallel.
  const lat::Lattice l =
      small_lattice(mess::model_profile("seed"), {29, 29, 29}, {{10, 10, 8}, {14, 14, 20}});
  const int threads = omp_get_max_threads();
  for (const int t : {1, 2, 3}) {
    omp_set_num_threads(t);
    expect_matches_single_process(l, 4.0, std::to_string(t) + " threads");
  }
  omp_set_num_threads(threads);
}

TEST(DistributedElastic, RefusesMismatchedInput) {
  const lat::Lattice l = small_lattice(mess::model_profile("physical"), {3, 3, 3});
  const lat::Lattice other = small_lattice(mess::model_profile("physical"), {3, 3, 4});
  const mess::LatticeDecomposition decomposition(l.shape, MPI_COMM_WORLD);
  EXPECT_THROW(mess::DistributedElastic(other, decomposition, 1.0), std::invalid_argument);
  EXPECT_THROW(mess::DistributedElastic(l, decomposition, 0.0), std::invalid_argument);
  EXPECT_THROW(mess::LatticeDecomposition(l.shape, MPI_COMM_WORLD, {-1, 0, 0}),
               std::invalid_argument);
  // Twice the processes there are; more processes along x than the grid has nodes.
  EXPECT_THROW(mess::LatticeDecomposition(l.shape, MPI_COMM_WORLD, {2 * world_size(), 1, 1}),
               std::invalid_argument);
  EXPECT_FALSE(mess::LatticeDecomposition::can_split(l.shape, 5, {5, 1, 1}));
  EXPECT_FALSE(mess::LatticeDecomposition::can_split(l.shape, 5));
  EXPECT_TRUE(mess::LatticeDecomposition::can_split(l.shape, 4, {0, 0, 1}));
  EXPECT_TRUE(mess::LatticeDecomposition::can_split(l.shape, 8, {2, 0, 0}));
  EXPECT_FALSE(mess::LatticeDecomposition::can_split(l.shape, 8, {0, 3, 0}));
  Vec v = decomposition.create_global_vector();
  EXPECT_THROW(decomposition.scatter(other.positions, v), std::invalid_argument);
  (void)VecDestroy(&v);
}
