// minimise() with its evaluations split over MPI processes (MinimiserOptions::distributed,
// distributed/distributed_evaluator.hpp), every process relaxing its own copy of the same
// system: the relaxed state and M are bitwise those of a single-process minimise() and the
// same on every process, the evaluation count the same, for the seed profile (its
// conservative phase, then the forces-only phase on the centre voxel's forces) with all faces
// held, with the plain and with the multilevel preconditioner. Also the helpers' collective
// contracts (sum_in_rank_order, any_process). Run on one process by ctest and on two and three in
// mess_distributed_two_ranks/_three_ranks.

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <memory>
#include <utility>
#include <vector>

#include "../support/mess_test_support.hpp"
#include "mpi_test_support.hpp"
#include "mresim/mess/distributed/distributed_evaluator.hpp"
#include "mresim/mess/distributed/lattice_decomposition.hpp"
#include "mresim/mess/distributed/mpi_job.hpp"
#include "mresim/mess/profile/model_profile.hpp"
#include "mresim/mess/solvers/amg_preconditioner.hpp"
#include "mresim/mess/solvers/minimiser.hpp"
#include "mresim/mess/system/fixed_order.hpp"

namespace mess = mresim::mess;
namespace lat = mresim::lattice;
using mess::testing::everywhere;
using mess::testing::small_lattice;
using mess::testing::tesla;
using mess::testing::world_rank;

namespace {

// Two n_d = 1 particles of the seed profile at 50 mT along z, every face held. The default
// lattice has one kSumBlock block of free coordinates (1,260), the larger one three (8,349).
mess::MessSystem held_pair(std::array<int, 3> cells = {6, 7, 10},
                           std::vector<std::array<int, 3>> centres = {{2, 3, 2}, {3, 3, 6}}) {
  const mess::ModelProfile profile = mess::model_profile("seed");
  mess::MessSystem system = mess::MessSystem::make(small_lattice(profile, cells, centres),
                                                   tesla(0.0, 0.01, 0.05), profile);
  mess::BoundaryConstraints held = mess::BoundaryConstraints::none(system.node_count());
  for (const lat::Face f : {lat::Face::left, lat::Face::right, lat::Face::front, lat::Face::back,
                            lat::Face::bottom, lat::Face::top}) {
    held.fix_face(system.lattice().shape, f, system.lattice().positions);
  }
  system.set_constraints(held);
  return system;
}

// Relaxes `single` on this process alone and a copy of it over all processes, both with
// `options`, and checks that both converge to bitwise the same positions and M with the same
// evaluations. Returns the split relaxation's result (the same on every process) and the single
// one's.
std::pair<mess::MinimiserResult, mess::MinimiserResult> expect_split_relaxation_bitwise(
    mess::MessSystem& single, mess::MinimiserOptions options = {}) {
  mess::MessSystem split = single;
  const mess::MinimiserResult a = mess::minimise(single, options);
  options.distributed = std::make_shared<mess::DistributedEvaluator>(MPI_COMM_WORLD);
  const mess::MinimiserResult b = mess::minimise(split, options);
  EXPECT_TRUE(a.converged) << mess::to_string(a.status);
  EXPECT_TRUE(everywhere(b.converged)) << mess::to_string(b.status);
  EXPECT_EQ(a.evaluations, b.evaluations);
  EXPECT_TRUE(everywhere(split.positions() == single.positions()))
      << "largest difference " << (split.positions() - single.positions()).cwiseAbs().maxCoeff();
  EXPECT_TRUE(everywhere(split.magnetizations() == single.magnetizations()));
  return {b, a};
}

}  // namespace

TEST(DistributedMinimise, RelaxesToTheSingleProcessStateBitwise) {
  mess::MessSystem single = held_pair();
  const auto [b, a] = expect_split_relaxation_bitwise(single);
  EXPECT_TRUE(a.forces_only_phase);  // the seed's second phase ran in both
  EXPECT_EQ(a.forces_only_phase, b.forces_only_phase);
  EXPECT_NEAR(b.final.potential, a.final.potential, 1e-13 * std::abs(a.final.potential));
  // The same totals on every process: process 0's, sent to all, equal each one's own.
  double potential = b.final.potential;
  MPI_Bcast(&potential, 1, MPI_DOUBLE, 0, MPI_COMM_WORLD);
  EXPECT_TRUE(everywhere(potential == b.final.potential));
}

// The L-BFGS pairs split over the processes (each stores its own blocks) with the evaluations.
TEST(DistributedMinimise, RelaxesALatticeOfSeveralBlocksToTheSingleProcessStateBitwise) {
  mess::MessSystem single = held_pair({12, 12, 24}, {{5, 6, 8}, {6, 6, 14}});
  const auto& shape = single.lattice().shape;
  const long free_coordinates = 3L * (shape.nx() - 2) * (shape.ny() - 2) * (shape.nz() - 2);
  ASSERT_GT(free_coordinates, 2 * mess::detail::kSumBlock);
  const auto [b, a] = expect_split_relaxation_bitwise(single);
  EXPECT_TRUE(a.forces_only_phase);
}

// The multilevel preconditioner (the default on lattices of 40,000 nodes or more, so at full
// size), forced here on a small lattice: every process builds and applies it whole, to the same
// whole vector, so the split relaxation stays bitwise the single-process one.
TEST(DistributedMinimise, RelaxesWithTheMultilevelPreconditionerToTheSingleProcessStateBitwise) {
  mess::MessSystem single = held_pair({12, 12, 24}, {{5, 6, 8}, {6, 6, 14}});
  mess::MinimiserOptions options;
  options.lbfgs_preconditioner = mess::LbfgsPreconditioner::multilevel;
  const auto [b, a] = expect_split_relaxation_bitwise(single, options);
  EXPECT_TRUE(a.forces_only_phase);
  // The correction was built and used: the path differs from the plain preconditioner's.
  mess::MessSystem plain = held_pair({12, 12, 24}, {{5, 6, 8}, {6, 6, 14}});
  (void)mess::minimise(plain);
  EXPECT_FALSE(plain.positions() == single.positions());
}

TEST(DistributedMinimise, NewtonIsRefused) {
  mess::MinimiserOptions options;
  options.method = mess::MinimiserMethod::newton;
  options.distributed = std::make_shared<mess::DistributedEvaluator>(MPI_COMM_WORLD);
  EXPECT_THROW(options.validate(), std::invalid_argument);
}

TEST(DistributedHelpers, SumInRankOrderAndAnyProcess) {
  const int rank = world_rank();
  int size = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  // Rank r contributes r + 1 and 1e16 - r: exact sums the rank order must reproduce.
  const std::vector<double> local = {rank + 1.0, 1e16 - rank};
  std::vector<double> total(2, 0.0);
  mess::sum_in_rank_order(MPI_COMM_WORLD, local.data(), total.data(), 2);
  double expected_second = 0.0;
  for (int r = 0; r < size; ++r) expected_second += 1e16 - r;
  EXPECT_EQ(total[0], size * (size + 1) / 2.0);
  EXPECT_EQ(total[1], expected_second);
  // any_process: true on every process when one has the flag (when launched by mpirun; a
  // process not started by a launcher is a job of one).
  const bool launched = mess::started_by_mpi_launcher();
  EXPECT_EQ(mess::any_process(rank == size - 1), true);
  EXPECT_EQ(mess::any_process(false), false);
  EXPECT_EQ(mess::mpi_job().size, launched ? size : 1);
}
