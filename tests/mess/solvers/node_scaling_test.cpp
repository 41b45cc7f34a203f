// The node blocks of the minimisers' preconditioner (solvers/preconditioner.hpp, "Node blocks";
// solver.node_scaling): built at a deformed state, each free polymer node is scaled by the
// inverse of its 3 x 3 block of the stiffness terms, summed here independently from the same
// terms; P stays symmetric positive definite and bitwise the same on every thread count; built
// at rest, or with NodeScaling::diagonal, it is the diagonal preconditioner; and the minimiser
// with the multilevel preconditioner reaches the same state with either scaling.

#include <gtest/gtest.h>
#include <omp.h>

#include <Eigen/Dense>
#include <cmath>
#include <memory>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "../support/mess_test_support.hpp"
#include "../support/multilevel_test_support.hpp"
#include "../support/small_runs.hpp"
#include "mresim/mess/solvers/minimiser.hpp"
#include "mresim/mess/solvers/preconditioner.hpp"
#include "mresim/mess/solvers/stiffness_terms.hpp"

namespace mess = mresim::mess;
namespace lat = mresim::lattice;
using mess::testing::faces_held;
using mess::testing::small_lattice;
using mess::testing::tesla;
using mess::testing::uniform_random_vector;

namespace {

constexpr double kScalingForceScale = 1e-9;  // N: any positive scale

// A lattice of `cells` with one particle in the middle, its bottom face held, every free
// coordinate displaced by up to 0.1 l_e (fixed seed): a state where the nodes' blocks are full.
struct DeformedSystem {
  explicit DeformedSystem(std::array<int, 3> cells)
      : sys(mess::MessSystem::make(small_lattice(mess::model_profile("physical"), cells,
                                                 {{cells[0] / 2, cells[1] / 2, cells[2] / 2}}),
                                   Eigen::Vector3d::Zero(), mess::model_profile("physical"))) {
    const lat::Lattice& l = sys.lattice();
    sys.set_constraints(faces_held(l, {lat::Face::bottom}));
    map = std::make_unique<mess::DofMap>(sys.constraints(), l.positions, l.element_length);
    std::mt19937 gen(17);
    std::uniform_real_distribution<double> u(-0.1, 0.1);
    x = l.positions;
    for (Eigen::Index n = 0; n < x.cols(); ++n) {
      for (int a = 0; a < 3; ++a) {
        if (map->dof_of(n, a) >= 0) x(a, n) += u(gen) * l.element_length;
      }
    }
    sys.set_positions(x);
  }
  mess::MessSystem sys;
  std::unique_ptr<mess::DofMap> map;
  Eigen::Matrix3Xd x;
};

bool is_particle_node(const lat::Lattice& l, std::int64_t n) {
  return !l.particle_of_node.empty() && l.particle_of_node[static_cast<std::size_t>(n)] >= 0;
}

// Each node's 3 x 3 block of the stiffness terms at `x`, scaled as the preconditioner's
// variables (l_e / force scale).
std::vector<Eigen::Matrix3d> stiffness_blocks(const DeformedSystem& d) {
  const lat::Lattice& l = d.sys.lattice();
  std::vector<Eigen::Matrix3d> blocks(static_cast<std::size_t>(l.node_count()),
                                      Eigen::Matrix3d::Zero());
  const double scale = l.element_length / kScalingForceScale;
  mess::for_each_stiffness_term(
      l, &d.x, *d.map, d.sys.settings().elastic.volume_force_factor, scale,
      [&](std::int64_t i, std::int64_t j, const Eigen::Vector3d& u, double c) {
        blocks[static_cast<std::size_t>(i)] += c * u * u.transpose();
        blocks[static_cast<std::size_t>(j)] += c * u * u.transpose();
      },
      [&](const auto& element, const lat::CellVertices& g, double c) {
        for (std::size_t v = 0; v < 8; ++v) {
          blocks[static_cast<std::size_t>(element[v])] += c * g[v] * g[v].transpose();
        }
      });
  return blocks;
}

TEST(NodeScaling, EachFreePolymerNodeTakesTheInverseOfItsStiffnessBlock) {
  const DeformedSystem d({6, 6, 8});
  const lat::Lattice& l = d.sys.lattice();
  const mess::DofMap& map = *d.map;
  const mess::RigidParticlePreconditioner blocks(d.sys, map, kScalingForceScale, false, &d.x);
  const mess::RigidParticlePreconditioner diagonal(d.sys, map, kScalingForceScale, false, &d.x,
                                                   nullptr, mess::NodeScaling::diagonal);
  const std::vector<Eigen::Matrix3d> reference = stiffness_blocks(d);
  const Eigen::VectorXd v = uniform_random_vector(map.size(), 5);
  const Eigen::VectorXd with_blocks = blocks.apply(map, v);
  const Eigen::VectorXd with_diagonal = diagonal.apply(map, v);
  Eigen::Index free_polymer_nodes = 0;
  for (std::int64_t n = 0; n < l.node_count(); ++n) {
    const Eigen::Index k = map.dof_of(n, 0);
    if (is_particle_node(l, n)) {
      // The particle's own scaling is the same either way.
      for (int a = 0; a < 3; ++a) {
        const Eigen::Index kp = map.dof_of(n, a);
        if (kp >= 0) EXPECT_EQ(with_blocks[kp], with_diagonal[kp]) << "node " << n;
      }
      continue;
    }
    const Eigen::Matrix3d& b = reference[static_cast<std::size_t>(n)];
    if (k < 0 || map.dof_of(n, 1) < 0 || map.dof_of(n, 2) < 0) {
      // A held coordinate: each free one keeps its diagonal.
      for (int a = 0; a < 3; ++a) {
        const Eigen::Index ka = map.dof_of(n, a);
        if (ka < 0) continue;
        EXPECT_NEAR(with_blocks[ka], v[ka] / b(a, a), 1e-12 * std::abs(v[ka] / b(a, a)));
        EXPECT_EQ(with_blocks[ka], with_diagonal[ka]);
      }
      continue;
    }
    ++free_polymer_nodes;
    const Eigen::Vector3d expected = b.inverse() * v.segment<3>(k);
    const Eigen::Vector3d diagonal_expected = v.segment<3>(k).cwiseQuotient(b.diagonal());
    EXPECT_LT((with_blocks.segment<3>(k) - expected).norm(), 1e-12 * expected.norm())
        << "node " << n;
    EXPECT_LT((with_diagonal.segment<3>(k) - diagonal_expected).norm(),
              1e-12 * diagonal_expected.norm())
        << "node " << n;
  }
  // Every free polymer node's block is positive definite here: all of them take it.
  EXPECT_GT(free_polymer_nodes, 100);
  EXPECT_EQ(blocks.block_nodes(), free_polymer_nodes);
  EXPECT_EQ(diagonal.block_nodes(), 0);
  // The blocks are not diagonal at this state: the two scalings differ.
  EXPECT_GT((with_blocks - with_diagonal).norm(), 1e-3 * with_diagonal.norm());
}

TEST(NodeScaling, AtRestThePreconditionerKeepsItsDiagonal) {
  const DeformedSystem d({6, 6, 8});
  const mess::DofMap& map = *d.map;
  const mess::RigidParticlePreconditioner blocks(d.sys, map, kScalingForceScale, true);
  const mess::RigidParticlePreconditioner diagonal(d.sys, map, kScalingForceScale, true, nullptr,
                                                   nullptr, mess::NodeScaling::diagonal);
  EXPECT_EQ(blocks.block_nodes(), 0);
  const Eigen::VectorXd v = uniform_random_vector(map.size(), 6);
  EXPECT_EQ(blocks.apply(map, v), diagonal.apply(map, v));
}

// With the multilevel correction: symmetric, positive definite, and bitwise the same on 1, 2,
// 3 and 8 threads, on a lattice large enough for the blocks' parallel loop (over 16,384 nodes).
TEST(NodeScaling, StaysSymmetricPositiveDefiniteAndThreadIndependent) {
  const DeformedSystem d({26, 26, 26});
  const mess::DofMap& map = *d.map;
  const mess::RigidParticlePreconditioner p(d.sys, map, kScalingForceScale, true, &d.x);
  ASSERT_NE(p.multilevel(), nullptr);
  ASSERT_GT(p.block_nodes(), 16384);
  const Eigen::VectorXd u = uniform_random_vector(map.size(), 7);
  const Eigen::VectorXd v = uniform_random_vector(map.size(), 8);
  const Eigen::VectorXd pu = p.apply(map, u);
  const Eigen::VectorXd pv = p.apply(map, v);
  EXPECT_NEAR(u.dot(pv), v.dot(pu), 1e-10 * std::sqrt(u.dot(pu) * v.dot(pv)));
  EXPECT_GT(u.dot(pu), 0.0);
  EXPECT_GT(v.dot(pv), 0.0);
  const int threads = omp_get_max_threads();
  for (const int t : {1, 2, 3, 8}) {
    omp_set_num_threads(t);
    EXPECT_EQ(p.apply(map, v), pv) << t << " threads";
  }
  omp_set_num_threads(threads);
}

// L-BFGS with the multilevel preconditioner reaches the same state with either scaling: a pair
// drawn together at 100 mT (physical profile, all faces held), to 1e-9 k_eff l_e.
TEST(NodeScaling, MinimiserReachesTheSameStateWithEitherScaling) {
  const auto relax = [](mess::NodeScaling scaling) {
    const mess::ModelProfile& profile = mess::model_profile("physical");
    mess::MessSystem sys = mess::MessSystem::make(
        small_lattice(profile, {9, 9, 14}, {{4, 4, 4}, {4, 4, 9}}), tesla(0.0, 0.0, 0.1), profile);
    const lat::Lattice& l = sys.lattice();
    sys.set_constraints(faces_held(l, {lat::Face::left, lat::Face::right, lat::Face::front,
                                       lat::Face::back, lat::Face::bottom, lat::Face::top}));
    sys.settings().magnetization.atol = 1e-11;
    sys.settings().magnetization.rtol = 1e-11;
    mess::MinimiserOptions options;
    options.force_tolerance = 1e-9;
    options.lbfgs_preconditioner = mess::LbfgsPreconditioner::multilevel;
    options.node_scaling = scaling;
    const mess::MinimiserResult r = mess::minimise(sys, options);
    EXPECT_TRUE(r.converged) << mess::to_string(r.status);
    return std::pair{Eigen::Matrix3Xd(sys.positions() / l.element_length), r.iterations};
  };
  const auto [blocks, blocks_iterations] = relax(mess::NodeScaling::blocks);
  const auto [diagonal, diagonal_iterations] = relax(mess::NodeScaling::diagonal);
  EXPECT_LT((blocks - diagonal).cwiseAbs().maxCoeff(), 1e-6);
  EXPECT_NE(blocks, diagonal);  // the two took different paths
  EXPECT_GT(blocks_iterations, 0);
  EXPECT_GT(diagonal_iterations, 0);
}

// solver.node_scaling: "blocks" by default, and "diagonal" read (node_scaling_bench runs both).
TEST(NodeScaling, RunFilesChooseTheScaling) {
  namespace mc = mresim::mess_config;
  namespace mp = mresim::mess_protocol;
  const std::string toml = mp::testing::small_hysteresis(0.03, 3);
  const mc::MessSpec defaults = mp::testing::spec_of(toml);
  EXPECT_EQ(defaults.solver.node_scaling, mess::NodeScaling::blocks);
  const mc::MessSpec diagonal =
      mp::testing::spec_of(toml + "\n[solver]\nnode_scaling = \"diagonal\"\n");
  EXPECT_EQ(diagonal.solver.node_scaling, mess::NodeScaling::diagonal);
}

}  // namespace
