// The multilevel correction of L-BFGS's preconditioner (solvers/multilevel_correction.hpp):
// against its formula built here from dense matrices, bitwise the same on every thread count,
// left out where nothing is held; the preconditioner cache; and the minimiser with it.
#include "mresim/mess/solvers/multilevel_correction.hpp"

#include <gtest/gtest.h>
#include <omp.h>

#include <Eigen/Dense>
#include <array>
#include <random>
#include <vector>

#include "../support/mess_test_support.hpp"
#include "mresim/mess/solvers/minimiser.hpp"
#include "mresim/mess/solvers/preconditioner.hpp"

namespace mess = mresim::mess;
namespace lat = mresim::lattice;
using mess::testing::small_lattice;
using mess::testing::tesla;

namespace {

constexpr double kForceScale = 1e-9;  // N: any positive scale

Eigen::VectorXd random_vector(Eigen::Index n, unsigned seed) {
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::VectorXd v(n);
  for (Eigen::Index i = 0; i < n; ++i) v[i] = u(gen);
  return v;
}

Eigen::VectorXd apply(const mess::MultilevelCorrection& c, const mess::DofMap& map,
                      const Eigen::VectorXd& v) {
  Eigen::VectorXd w = Eigen::VectorXd::Zero(v.size());
  c.add_to(map, v, w);
  return w;
}

// The planes of every level along one axis of n lattice planes: every second plane of the
// finer level and its last one.
std::vector<std::vector<int>> level_planes(int n, int levels) {
  std::vector<std::vector<int>> out;
  std::vector<int> finer(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) finer[static_cast<std::size_t>(i)] = i;
  for (int l = 0; l < levels; ++l) {
    std::vector<int> coarse;
    for (std::size_t i = 0; i < finer.size(); i += 2) coarse.push_back(finer[i]);
    if (coarse.back() != finer.back()) coarse.push_back(finer.back());
    out.push_back(coarse);
    finer = coarse;
  }
  return out;
}

// The hat function of coarse plane j (planes p) at lattice plane i.
double hat(const std::vector<int>& p, std::size_t j, int i) {
  if (i == p[j]) return 1.0;
  if (j > 0 && i > p[j - 1] && i < p[j]) {
    return static_cast<double>(i - p[j - 1]) / (p[j] - p[j - 1]);
  }
  if (j + 1 < p.size() && i > p[j] && i < p[j + 1]) {
    return static_cast<double>(p[j + 1] - i) / (p[j + 1] - p[j]);
  }
  return 0.0;
}

// The header's formula, from dense matrices: sum over levels of Phi B Phi^T, B the inverse
// diagonal of Phi^T A Phi on every level but the coarsest, its inverse on the coarsest.
Eigen::MatrixXd reference_correction(const mess::MessSystem& sys, const mess::DofMap& map,
                                     int levels) {
  const lat::Lattice& l = sys.lattice();
  const Eigen::Index dofs = map.own_dofs();
  const Eigen::MatrixXd full = Eigen::MatrixXd(sys.elastic_hessian());
  Eigen::MatrixXd a(dofs, dofs);
  for (Eigen::Index i = 0; i < dofs; ++i) {
    for (Eigen::Index j = 0; j < dofs; ++j)
      a(i, j) = full(map.coordinate_of(i), map.coordinate_of(j));
  }
  a *= l.element_length / kForceScale;
  std::array<std::vector<std::vector<int>>, 3> planes;
  for (int axis = 0; axis < 3; ++axis) planes[axis] = level_planes(l.shape.nodes[axis], levels);

  Eigen::MatrixXd c = Eigen::MatrixXd::Zero(dofs, dofs);
  for (int level = 0; level < levels; ++level) {
    const auto& px = planes[0][level];
    const auto& py = planes[1][level];
    const auto& pz = planes[2][level];
    const Eigen::Index points = static_cast<Eigen::Index>(px.size() * py.size() * pz.size());
    Eigen::MatrixXd phi = Eigen::MatrixXd::Zero(dofs, 3 * points);
    for (Eigen::Index k = 0; k < dofs; ++k) {
      const std::int64_t coordinate = map.coordinate_of(k);
      const auto node = static_cast<int>(coordinate / 3);
      const int axis = static_cast<int>(coordinate % 3);
      const auto [ix, iy, iz] = l.shape.node_coordinates(node);
      for (std::size_t jy = 0; jy < py.size(); ++jy) {
        for (std::size_t jx = 0; jx < px.size(); ++jx) {
          for (std::size_t jz = 0; jz < pz.size(); ++jz) {
            const auto point = static_cast<Eigen::Index>(jz + pz.size() * (jx + px.size() * jy));
            phi(k, 3 * point + axis) = hat(px, jx, ix) * hat(py, jy, iy) * hat(pz, jz, iz);
          }
        }
      }
    }
    const Eigen::MatrixXd coarse = phi.transpose() * a * phi;
    std::vector<Eigen::Index> used;
    for (Eigen::Index q = 0; q < coarse.rows(); ++q) {
      if (coarse(q, q) > 0.0) used.push_back(q);
    }
    if (level + 1 < levels) {
      Eigen::VectorXd inverse = Eigen::VectorXd::Zero(coarse.rows());
      for (const Eigen::Index q : used) inverse[q] = 1.0 / coarse(q, q);
      c += phi * inverse.asDiagonal() * phi.transpose();
    } else {
      const auto n = static_cast<Eigen::Index>(used.size());
      Eigen::MatrixXd reduced(n, n);
      Eigen::MatrixXd phi_used(dofs, n);
      for (Eigen::Index i = 0; i < n; ++i) {
        phi_used.col(i) = phi.col(used[i]);
        for (Eigen::Index j = 0; j < n; ++j) reduced(i, j) = coarse(used[i], used[j]);
      }
      c += phi_used * reduced.ldlt().solve(phi_used.transpose());
    }
  }
  return c;
}

mess::BoundaryConstraints faces_held(const lat::Lattice& l,
                                     std::initializer_list<lat::Face> faces) {
  mess::BoundaryConstraints c = mess::BoundaryConstraints::none(l.node_count());
  for (const lat::Face f : faces) c.fix_face(l.shape, f, l.positions);
  return c;
}

}  // namespace

// 9 x 9 x 9 nodes with a stiff particle, two faces held: levels of 5^3 and 3^3 points scaled by
// their diagonals, the coarsest 2^3 solved exactly (it is the first with at most 1/64 of the
// lattice's coordinates). The correction is the formula to rounding, for both profiles (the
// seed's volume forces are 4x).
TEST(MultilevelCorrection, IsTheGalerkinFormulaOnEveryLevel) {
  for (const char* profile_name : {"physical", "seed"}) {
    const mess::ModelProfile& profile = mess::model_profile(profile_name);
    mess::MessSystem sys = mess::MessSystem::make(small_lattice(profile, {8, 8, 8}, {{4, 4, 4}}),
                                                  Eigen::Vector3d::Zero(), profile);
    const lat::Lattice& l = sys.lattice();
    sys.set_constraints(faces_held(l, {lat::Face::bottom, lat::Face::left}));
    const mess::DofMap map(sys.constraints(), l.positions, l.element_length);
    const mess::MultilevelCorrection c(l, sys.settings().elastic.volume_force_factor, map,
                                       kForceScale);
    ASSERT_EQ(c.levels(), 3);
    EXPECT_EQ(c.level_size(1), 3 * 125);
    EXPECT_EQ(c.level_size(3), 3 * 8);
    const Eigen::MatrixXd expected = reference_correction(sys, map, 3);
    for (unsigned seed = 1; seed <= 3; ++seed) {
      const Eigen::VectorXd v = random_vector(map.size(), seed);
      const Eigen::VectorXd want = expected * v;
      EXPECT_LT((apply(c, map, v) - want).norm(), 1e-11 * want.norm()) << profile_name;
    }
  }
}

// Symmetric and positive definite, as an initial inverse Hessian must be.
TEST(MultilevelCorrection, IsSymmetricPositiveDefinite) {
  const mess::ModelProfile& profile = mess::model_profile("seed");
  mess::MessSystem sys = mess::MessSystem::make(small_lattice(profile, {10, 12, 14}, {{5, 6, 7}}),
                                                Eigen::Vector3d::Zero(), profile);
  const lat::Lattice& l = sys.lattice();
  sys.set_constraints(faces_held(l, {lat::Face::bottom, lat::Face::top}));
  const mess::DofMap map(sys.constraints(), l.positions, l.element_length);
  const mess::MultilevelCorrection c(l, sys.settings().elastic.volume_force_factor, map,
                                     kForceScale);
  const Eigen::VectorXd v = random_vector(map.size(), 11);
  const Eigen::VectorXd w = random_vector(map.size(), 12);
  const double vcw = v.dot(apply(c, map, w));
  EXPECT_NEAR(vcw, w.dot(apply(c, map, v)), 1e-12 * std::abs(vcw));
  EXPECT_GT(v.dot(apply(c, map, v)), 0.0);
  EXPECT_GT(w.dot(apply(c, map, w)), 0.0);
  // It reads the lattice through the map it is given: one with other free coordinates is refused.
  sys.set_constraints(faces_held(l, {lat::Face::bottom}));
  const mess::DofMap other(sys.constraints(), l.positions, l.element_length);
  Eigen::VectorXd out = Eigen::VectorXd::Zero(other.size());
  EXPECT_THROW(c.add_to(other, random_vector(other.size(), 13), out), std::invalid_argument);
}

// The grid sweeps are split over threads by grid lines: bitwise the same result for 1, 2 and 3
// threads (30 x 30 x 30 cells: large enough for the parallel sweeps).
TEST(MultilevelCorrection, IsBitwiseTheSameOnEveryThreadCount) {
  const mess::ModelProfile& profile = mess::model_profile("seed");
  mess::MessSystem sys =
      mess::MessSystem::make(small_lattice(profile, {30, 30, 30}, {{10, 15, 15}, {20, 15, 15}}),
                             Eigen::Vector3d::Zero(), profile);
  const lat::Lattice& l = sys.lattice();
  sys.set_constraints(faces_held(l, {lat::Face::left, lat::Face::right, lat::Face::front,
                                     lat::Face::back, lat::Face::bottom, lat::Face::top}));
  const mess::DofMap map(sys.constraints(), l.positions, l.element_length);
  const int threads = omp_get_max_threads();
  omp_set_num_threads(1);
  const mess::MultilevelCorrection c(l, sys.settings().elastic.volume_force_factor, map,
                                     kForceScale);
  EXPECT_GE(c.levels(), 2);
  const Eigen::VectorXd v = random_vector(map.size(), 5);
  const Eigen::VectorXd one = apply(c, map, v);
  for (const int t : {2, 3}) {
    omp_set_num_threads(t);
    const mess::MultilevelCorrection other(l, sys.settings().elastic.volume_force_factor, map,
                                           kForceScale);
    EXPECT_EQ(apply(other, map, v), one) << t << " threads";
    EXPECT_EQ(apply(c, map, v), one) << t << " threads";
  }
  omp_set_num_threads(threads);
}

// With nothing held the lattice's rigid motions make the coarsest level singular: the
// correction refuses, and the preconditioner goes on without it.
TEST(MultilevelCorrection, IsLeftOutWhereNothingIsHeld) {
  const mess::ModelProfile& profile = mess::model_profile("physical");
  const mess::MessSystem sys =
      mess::MessSystem::make(small_lattice(profile, {6, 6, 6}), Eigen::Vector3d::Zero(), profile);
  const lat::Lattice& l = sys.lattice();
  const mess::DofMap map(sys.constraints(), l.positions, l.element_length);
  EXPECT_THROW(mess::MultilevelCorrection(l, 1.0, map, kForceScale), std::runtime_error);
  const mess::RigidParticlePreconditioner p(sys, map, kForceScale, true);
  EXPECT_EQ(p.multilevel(), nullptr);
  const Eigen::VectorXd v = random_vector(map.size(), 3);
  const mess::RigidParticlePreconditioner plain(sys, map, kForceScale, false);
  EXPECT_EQ(p.apply(map, v), plain.apply(map, v));
}

// A run keeps one preconditioner while the free coordinates stay, and builds a new one when
// they change (another face held) or the multilevel choice does.
TEST(PreconditionerCache, KeepsOnePreconditionerWhileTheFreeCoordinatesStay) {
  const mess::ModelProfile& profile = mess::model_profile("physical");
  mess::MessSystem sys =
      mess::MessSystem::make(small_lattice(profile, {6, 6, 6}), Eigen::Vector3d::Zero(), profile);
  const lat::Lattice& l = sys.lattice();
  sys.set_constraints(faces_held(l, {lat::Face::bottom}));
  mess::PreconditionerCache cache;
  const mess::DofMap map(sys.constraints(), l.positions, l.element_length);
  const auto first = cache.get(sys, map, kForceScale, true);
  ASSERT_NE(first->multilevel(), nullptr);
  // Other prescribed values of the same held coordinates: the same free coordinates.
  Eigen::Matrix3Xd moved = l.positions;
  moved.row(0).array() += 0.1 * l.element_length;
  mess::BoundaryConstraints shifted = mess::BoundaryConstraints::none(l.node_count());
  shifted.fix_face(l.shape, lat::Face::bottom, moved);
  sys.set_constraints(shifted);
  const mess::DofMap same(sys.constraints(), l.positions, l.element_length);
  EXPECT_EQ(cache.get(sys, same, kForceScale, true), first);
  EXPECT_EQ(cache.builds(), 1);
  sys.set_constraints(faces_held(l, {lat::Face::bottom, lat::Face::top}));
  const mess::DofMap other(sys.constraints(), l.positions, l.element_length);
  EXPECT_NE(cache.get(sys, other, kForceScale, true), first);
  EXPECT_EQ(cache.builds(), 2);
  EXPECT_EQ(cache.get(sys, other, kForceScale, false)->multilevel(), nullptr);
  EXPECT_EQ(cache.builds(), 3);
}

// L-BFGS with the multilevel preconditioner reaches the state L-BFGS reaches without it: a
// pair drawn together at 100 mT (physical profile, all faces held), both to 1e-9 k_eff l_e.
TEST(MultilevelCorrection, MinimiserReachesTheSameStateWithIt) {
  const auto relax = [](mess::LbfgsPreconditioner preconditioner) {
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
    options.lbfgs_preconditioner = preconditioner;
    const mess::MinimiserResult r = mess::minimise(sys, options);
    EXPECT_TRUE(r.converged) << mess::to_string(r.status);
    return std::pair{Eigen::Matrix3Xd(sys.positions() / l.element_length), r.iterations};
  };
  const auto [with, with_iterations] = relax(mess::LbfgsPreconditioner::multilevel);
  const auto [without, without_iterations] = relax(mess::LbfgsPreconditioner::rigid_particles);
  EXPECT_LT((with - without).cwiseAbs().maxCoeff(), 1e-6);
  // Below kMultilevelMinimumNodes `automatic` is the rigid-particle preconditioner, bitwise.
  const auto [automatic, automatic_iterations] = relax(mess::LbfgsPreconditioner::automatic);
  EXPECT_EQ(automatic, without);
  EXPECT_EQ(automatic_iterations, without_iterations);
  EXPECT_GT(with_iterations, 0);
}

// Where the lattice is large the polymer's long waves dominate, and the correction takes
// L-BFGS there in fewer iterations: a particle-free block whose top face is sheared,
// 24 x 24 x 24 cells, to 1e-8 k_eff l_e.
TEST(MultilevelCorrection, TakesFewerIterationsOnALargeShearedBlock) {
  const auto iterations = [](mess::LbfgsPreconditioner preconditioner) {
    const mess::ModelProfile& profile = mess::model_profile("physical");
    mess::MessSystem sys = mess::MessSystem::make(small_lattice(profile, {24, 24, 24}),
                                                  Eigen::Vector3d::Zero(), profile);
    const lat::Lattice& l = sys.lattice();
    Eigen::Matrix3Xd target = l.positions;
    const double height = l.box_lengths()[2];
    for (Eigen::Index n = 0; n < target.cols(); ++n) {
      // A bump: the top face moves along x by up to 0.5 l_e, most in its middle.
      const double sx = std::sin(M_PI * l.positions(0, n) / l.box_lengths()[0]);
      const double sy = std::sin(M_PI * l.positions(1, n) / l.box_lengths()[1]);
      if (l.positions(2, n) > height - 1e-3 * l.element_length) {
        target(0, n) += 0.5 * l.element_length * sx * sy;
      }
    }
    sys.set_constraints(faces_held(l, {lat::Face::bottom}));
    mess::BoundaryConstraints c = sys.constraints();
    c.fix_face(l.shape, lat::Face::top, target);
    sys.set_constraints(c);
    mess::MinimiserOptions options;
    options.force_tolerance = 1e-8;
    options.lbfgs_preconditioner = preconditioner;
    const mess::MinimiserResult r = mess::minimise(sys, options);
    EXPECT_TRUE(r.converged) << mess::to_string(r.status);
    return r.iterations;
  };
  const int with = iterations(mess::LbfgsPreconditioner::multilevel);
  const int without = iterations(mess::LbfgsPreconditioner::rigid_particles);
  EXPECT_LT(2 * with, without) << with << " against " << without;
}
