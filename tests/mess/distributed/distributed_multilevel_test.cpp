// The multilevel correction (solvers/multilevel_correction.hpp) built by several MPI processes,
// each level by one of them and shared (MpiBlockSplit): every process's correction is bitwise
// the one a single process builds alone, at rest and at a strained state, and a build that
// fails (nothing held: the coarsest level is singular) fails on every process instead of
// leaving one waiting. Run on one process by ctest (where nothing is shared) and on two and
// three in mess_distributed_two_ranks/_three_ranks, where the levels go to different processes.

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <array>
#include <stdexcept>
#include <vector>

#include "../support/mess_test_support.hpp"
#include "../support/multilevel_test_support.hpp"
#include "mpi_test_support.hpp"
#include "mresim/mess/distributed/mpi_block_split.hpp"
#include "mresim/mess/profile/model_profile.hpp"
#include "mresim/mess/solvers/multilevel_correction.hpp"
#include "mresim/mess/system/system_energy.hpp"

namespace mess = mresim::mess;
namespace lat = mresim::lattice;
using mess::testing::apply_correction;
using mess::testing::everywhere;
using mess::testing::faces_held;
using mess::testing::perturbed;
using mess::testing::small_lattice;
using mess::testing::uniform_random_vector;
using mess::testing::world_size;

namespace {

constexpr double kForceScale = 1e-9;  // N: any positive scale
// A small exactly solved level, so that the 16 x 16 x 24 lattice has three levels to deal out
// (on three processes, one each).
constexpr Eigen::Index kExactLimit = 200;

// Two seed-profile particles in a 16 x 16 x 24 cell lattice, every face held unless `free`.
mess::MessSystem pair_system(bool free = false) {
  const mess::ModelProfile& profile = mess::model_profile("seed");
  mess::MessSystem sys =
      mess::MessSystem::make(small_lattice(profile, {16, 16, 24}, {{8, 8, 8}, {8, 8, 16}}),
                             Eigen::Vector3d::Zero(), profile);
  if (free) return sys;
  sys.set_constraints(
      faces_held(sys.lattice(), {lat::Face::left, lat::Face::right, lat::Face::front,
                                 lat::Face::back, lat::Face::bottom, lat::Face::top}));
  return sys;
}

}  // namespace

TEST(DistributedMultilevel, BuildSharedOverProcessesIsBitwiseTheSingleProcessOne) {
  const mess::MessSystem sys = pair_system();
  const lat::Lattice& l = sys.lattice();
  const mess::DofMap map(sys.constraints(), l.positions, l.element_length);
  const double factor = sys.settings().elastic.volume_force_factor;
  const mess::MpiBlockSplit processes(MPI_COMM_WORLD);
  // At rest, and linearised at a strained state (every node moved by up to 0.05 l_e).
  const Eigen::Matrix3Xd state = perturbed(l.positions, 0.05 * l.element_length);
  const std::array<const Eigen::Matrix3Xd*, 2> states = {nullptr, &state};
  for (const Eigen::Matrix3Xd* at : states) {
    const mess::MultilevelCorrection alone(l, factor, map, kForceScale, at, kExactLimit);
    const mess::MultilevelCorrection shared(l, factor, map, kForceScale, at, kExactLimit,
                                            &processes);
    ASSERT_GE(shared.levels(), 3);
    ASSERT_TRUE(everywhere(shared.levels() == alone.levels()));
    for (const unsigned seed : {1U, 2U}) {
      const Eigen::VectorXd v = uniform_random_vector(map.size(), seed);
      const Eigen::VectorXd expected = apply_correction(alone, map, v);
      EXPECT_GT(v.dot(expected), 0.0);
      EXPECT_TRUE(everywhere(apply_correction(shared, map, v) == expected))
          << "seed " << seed << (at == nullptr ? " at rest" : " at the strained state");
    }
  }
  EXPECT_GE(world_size(), 1);
}

// With nothing held the coarsest level (built by the first process) is singular: every process
// throws, as a single process does (the preconditioner then leaves the correction out).
TEST(DistributedMultilevel, AFailedBuildFailsOnEveryProcess) {
  const mess::MessSystem sys = pair_system(/*free=*/true);
  const lat::Lattice& l = sys.lattice();
  const mess::DofMap map(sys.constraints(), l.positions, l.element_length);
  const mess::MpiBlockSplit processes(MPI_COMM_WORLD);
  bool threw = false;
  try {
    const mess::MultilevelCorrection shared(l, sys.settings().elastic.volume_force_factor, map,
                                            kForceScale, nullptr, kExactLimit, &processes);
  } catch (const std::runtime_error&) {
    threw = true;
  }
  EXPECT_TRUE(everywhere(threw));
}

// share_from hands every process the owner's values, length included.
TEST(DistributedMultilevel, ShareFromGivesEveryProcessTheOwnersValues) {
  const mess::MpiBlockSplit processes(MPI_COMM_WORLD);
  const int size = processes.processes();
  EXPECT_EQ(size, world_size());
  for (int owner = 0; owner < size; ++owner) {
    std::vector<double> values(static_cast<std::size_t>(processes.rank() + 1),
                               10.0 * processes.rank());
    processes.share_from(owner, values);
    EXPECT_TRUE(everywhere(values ==
                           std::vector<double>(static_cast<std::size_t>(owner + 1), 10.0 * owner)));
  }
  std::vector<double> values;
  EXPECT_THROW(processes.share_from(size, values), std::invalid_argument);
}
