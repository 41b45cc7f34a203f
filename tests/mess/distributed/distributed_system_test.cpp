// Tests of the distributed evaluation of the whole 3D potential (distributed/
// distributed_system.hpp) against MessSystem::evaluate on the same state: the gradient and the
// magnetizations bitwise, the centre terms' energies bitwise, the node sums (springs, volume,
// load) and the potential to 1e-13 relative; for both model profiles (the seed's centre-voxel
// centres and 4x volume forces), with an applied field, applied forces (the load term) and a
// magnetization re-solved at every evaluation from the same history. Run on one process by
// ctest and on two in `mess_distributed_two_ranks` (distributed_elastic_test.cpp).

#include "mresim/mess/distributed/distributed_system.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "../support/mess_test_support.hpp"
#include "mpi_test_support.hpp"
#include "mresim/config/table_reader.hpp"
#include "mresim/mess/profile/model_profile.hpp"
#include "mresim/mess/solvers/amg_preconditioner.hpp"
#include "mresim/mess/terms/energy_term.hpp"

namespace mess = mresim::mess;
using mess::testing::everywhere;
using mess::testing::perturbed;
using mess::testing::relative_difference;
using mess::testing::small_lattice;
using mess::testing::tesla;

namespace {

// Two n_d = 1 particles, 100 mT oblique, a pull on the top face's nodes; `terms`: the run
// file's [terms.<name>] tables (optional energy terms).
mess::MessSystem loaded_pair(const mess::ModelProfile& profile, const std::string& terms) {
  const auto root = mresim::config::TableReader::parse_string(terms, "distributed.toml");
  mess::MessSystem system =
      mess::MessSystem::make(small_lattice(profile, {6, 7, 10}, {{2, 3, 2}, {3, 3, 6}}),
                             tesla(0.02, 0.01, 0.1), profile, {}, mess::read_term_tables(root));
  Eigen::Matrix3Xd forces = Eigen::Matrix3Xd::Zero(3, system.node_count());
  const auto& shape = system.lattice().shape;
  for (int iy = 0; iy < shape.ny(); ++iy) {
    for (int ix = 0; ix < shape.nx(); ++ix) {
      forces.col(shape.node_index(ix, iy, shape.nz() - 1)) = Eigen::Vector3d(1e-9, 0.0, 3e-9);
    }
  }
  system.set_applied_forces(forces);
  return system;
}

void expect_system_matches_single_process(const mess::ModelProfile& profile,
                                          const std::string& terms = "") {
  SCOPED_TRACE(std::string(profile.name) + " profile");
  mess::MessSystem single = loaded_pair(profile, terms);
  (void)single.solve_magnetization();  // the same history for both
  mess::MessSystem distributed_copy = single;
  const Eigen::Matrix3Xd x = perturbed(single.positions(), 0.05 * single.length_scale(), 3);
  single.set_positions(x);
  Eigen::Matrix3Xd expected;
  const mess::Evaluation e = single.evaluate(&expected);

  mess::initialise_petsc();
  const mess::LatticeDecomposition decomposition(single.lattice().shape, MPI_COMM_WORLD);
  mess::DistributedSystem distributed(distributed_copy, decomposition);
  Vec positions = decomposition.create_global_vector();
  Vec gradient = decomposition.create_global_vector();
  decomposition.scatter(x, positions);
  const mess::Evaluation d = distributed.evaluate(positions, gradient);
  const Eigen::Matrix3Xd got = decomposition.gather(gradient);
  (void)VecDestroy(&positions);
  (void)VecDestroy(&gradient);

  EXPECT_TRUE(everywhere(got == expected))
      << "largest gradient difference " << (got - expected).cwiseAbs().maxCoeff();
  EXPECT_TRUE(everywhere(distributed.centres() == single.particle_centres()));
  EXPECT_TRUE(everywhere(distributed_copy.magnetizations() == single.magnetizations()));
  EXPECT_EQ(distributed_copy.magnetization_stats().solves, single.magnetization_stats().solves);
  for (std::size_t i = 0; i < e.energies.size(); ++i) {
    const std::string& name = e.energies.label(i).name;
    const bool node_sum = name == "springs" || name == "volume" || name == "load";
    const double difference = relative_difference(d.energies.value(i), e.energies.value(i));
    EXPECT_TRUE(everywhere(node_sum ? difference < 1e-13 : difference == 0.0))
        << name << ": " << d.energies.value(i) << " against " << e.energies.value(i);
  }
  EXPECT_NE(e.energies["load"], 0.0);
  EXPECT_TRUE(everywhere(relative_difference(d.potential, e.potential) < 1e-13));
  EXPECT_TRUE(everywhere(relative_difference(d.magnitude, e.magnitude) < 1e-13));
}

}  // namespace

TEST(DistributedSystem, EvaluationMatchesTheSingleProcessSystem) {
  expect_system_matches_single_process(mess::model_profile("physical"));
  expect_system_matches_single_process(mess::model_profile("seed"));
}

// The optional Kelvin-force term reads only the centres and magnetizations: evaluated on every
// process, its centre gradient shared by the owned particle nodes, as the magnetic terms are.
TEST(DistributedSystem, EvaluationWithTheFieldGradientTermMatches) {
  const std::string terms =
      "[terms.field_gradient]\ngradient = [-4e9, 1e9, 0.0, 1e9, -2e9, 3e9, 0.0, 3e9, 6e9]\n"
      "origin = [4.5e-6, 4.5e-6, 7e-6]\n";
  expect_system_matches_single_process(mess::model_profile("physical"), terms);
  expect_system_matches_single_process(mess::model_profile("seed"), terms);
  // The term is there and does something.
  mess::MessSystem system = loaded_pair(mess::model_profile("physical"), terms);
  (void)system.solve_magnetization();
  EXPECT_NE(system.evaluate(nullptr).energies["field_gradient"], 0.0);
}

// Every energy term the program registers has a distributed form (the refusal in the
// constructor and in the run-file check is for a term added without one), and a name that is
// no term is refused.
TEST(DistributedSystem, EveryRegisteredTermHasADistributedForm) {
  for (const mess::TermRegistration& r : mess::energy_term_registrations()) {
    EXPECT_TRUE(mess::DistributedSystem::supports(r.name)) << r.name;
  }
  EXPECT_FALSE(mess::DistributedSystem::supports("no_such_term"));
}
