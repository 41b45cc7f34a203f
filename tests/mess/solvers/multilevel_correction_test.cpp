// The multilevel correction of L-BFGS's preconditioner (solvers/multilevel_correction.hpp):
// against its formula built here from dense matrices, bitwise the same on every thread count,
// left out where nothing is held; the preconditioner cache; and the minimiser with it.
#include "mresim/mess/solvers/multilevel_correction.hpp"

#include <gtest/gtest.h>
#include <omp.h>

#include <Eigen/Dense>
#include <array>
#include <cmath>
#include <random>
#include <utility>
#include <vector>

#include "../support/mess_test_support.hpp"
#include "../support/multilevel_test_support.hpp"
#include "mresim/mess/solvers/minimiser.hpp"
#include "mresim/mess/solvers/preconditioner_cache.hpp"

namespace mess = mresim::mess;
namespace lat = mresim::lattice;
using mess::testing::apply_correction;
using mess::testing::faces_held;
using mess::testing::perturbed;
using mess::testing::small_lattice;
using mess::testing::tesla;
using mess::testing::uniform_random_vector;

namespace {

constexpr double kForceScale = 1e-9;  // N: any positive scale

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
// diagonal of Phi^T A Phi on every level but the coarsest, its inverse on the coarsest; A the
// free coordinates' block of `full` (3 N x 3 N, J/m^2).
Eigen::MatrixXd reference_correction(const lat::Lattice& l, const Eigen::MatrixXd& full,
                                     const mess::DofMap& map, int levels) {
  const Eigen::Index dofs = map.own_dofs();
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

// At rest the stiffness terms are the elastic Hessian itself.
Eigen::MatrixXd reference_correction(const mess::MessSystem& sys, const mess::DofMap& map,
                                     int levels) {
  return reference_correction(sys.lattice(), Eigen::MatrixXd(sys.elastic_hessian()), map, levels);
}

// The stiffness terms of stiffness_terms.hpp at positions x as a dense 3 N x 3 N matrix, from
// their definition: per spring k L/l u u^T, per cell force_factor kappa/V0 g g^T with g the
// cell's volume gradient at x; a spring or cell with a node that has a held coordinate at rest.
Eigen::MatrixXd stiffness_matrix(const lat::Lattice& l, const Eigen::Matrix3Xd& x,
                                 const mess::DofMap& map, double force_factor) {
  const auto n = static_cast<Eigen::Index>(3 * l.node_count());
  Eigen::MatrixXd h = Eigen::MatrixXd::Zero(n, n);
  const auto held = [&](std::int64_t node) {
    return map.dof_of(node, 0) < 0 || map.dof_of(node, 1) < 0 || map.dof_of(node, 2) < 0;
  };
  // Adds c z z^T, z given per node.
  const auto add = [&](const std::vector<std::pair<std::int64_t, Eigen::Vector3d>>& z, double c) {
    for (const auto& [i, zi] : z) {
      for (const auto& [j, zj] : z) h.block<3, 3>(3 * i, 3 * j) += c * zi * zj.transpose();
    }
  };
  for (std::size_t s = 0; s < l.springs.size(); ++s) {
    const std::int64_t i = l.springs.first[s];
    const std::int64_t j = l.springs.second(s);
    const bool rest = held(i) || held(j);
    const Eigen::Vector3d r = rest ? Eigen::Vector3d(l.positions.col(j) - l.positions.col(i))
                                   : Eigen::Vector3d(x.col(j) - x.col(i));
    const double c = l.springs.stiffness(s) * (rest ? 1.0 : l.springs.rest_length(s) / r.norm());
    add({{j, r.normalized()}, {i, -r.normalized()}}, c);
  }
  const double v0 = std::pow(l.element_length, 3);
  for (const auto& e : l.elements) {
    bool rest = false;
    for (const std::int32_t node : e) rest = rest || held(node);
    lat::CellVertices v;
    lat::CellVertices g;
    for (std::size_t k = 0; k < 8; ++k) v[k] = (rest ? l.positions : x).col(e[k]);
    (void)lat::cell_volume_and_gradient(v, g);
    std::vector<std::pair<std::int64_t, Eigen::Vector3d>> z;
    for (std::size_t k = 0; k < 8; ++k) z.emplace_back(e[k], g[k]);
    add(z, force_factor * std::abs(l.polymer.kappa) / v0);
  }
  return h;
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
      const Eigen::VectorXd v = uniform_random_vector(map.size(), seed);
      const Eigen::VectorXd want = expected * v;
      EXPECT_LT((apply_correction(c, map, v) - want).norm(), 1e-11 * want.norm()) << profile_name;
    }
  }
}

// Built at a deformed state it is the formula with the stiffness terms at that state
// (stiffness_terms.hpp): every node displaced at random by up to 0.2 l_e, a face held 0.5 l_e
// away; the springs and cells of the held nodes stay at rest wherever x puts those nodes. Also:
// built at the reference positions it is the one built at rest, to rounding.
TEST(MultilevelCorrection, IsTheGalerkinFormulaAtADeformedState) {
  const mess::ModelProfile& profile = mess::model_profile("seed");
  mess::MessSystem sys = mess::MessSystem::make(small_lattice(profile, {8, 8, 8}, {{4, 4, 4}}),
                                                Eigen::Vector3d::Zero(), profile);
  const lat::Lattice& l = sys.lattice();
  Eigen::Matrix3Xd x = l.positions;
  std::mt19937 gen(7);
  std::uniform_real_distribution<double> u(-0.2, 0.2);
  for (Eigen::Index n = 0; n < x.cols(); ++n) {
    for (int a = 0; a < 3; ++a) x(a, n) += u(gen) * l.element_length;
  }
  Eigen::Matrix3Xd top = x;
  top.row(0).array() += 0.5 * l.element_length;
  mess::BoundaryConstraints held = faces_held(l, {lat::Face::bottom});
  held.fix_face(l.shape, lat::Face::top, top);
  sys.set_constraints(held);
  const mess::DofMap map(sys.constraints(), l.positions, l.element_length);
  const double factor = sys.settings().elastic.volume_force_factor;
  const mess::MultilevelCorrection c(l, factor, map, kForceScale, &x);
  ASSERT_EQ(c.levels(), 3);
  const Eigen::MatrixXd expected =
      reference_correction(l, stiffness_matrix(l, x, map, factor), map, 3);
  const mess::MultilevelCorrection at_rest(l, factor, map, kForceScale);
  const mess::MultilevelCorrection at_reference(l, factor, map, kForceScale, &l.positions);
  for (unsigned seed = 1; seed <= 3; ++seed) {
    const Eigen::VectorXd v = uniform_random_vector(map.size(), seed);
    const Eigen::VectorXd want = expected * v;
    EXPECT_LT((apply_correction(c, map, v) - want).norm(), 1e-11 * want.norm());
    // The deformation changes it (else the check above could not tell the states apart).
    const Eigen::VectorXd rest = apply_correction(at_rest, map, v);
    EXPECT_GT((rest - want).norm(), 1e-3 * want.norm());
    EXPECT_LT((apply_correction(at_reference, map, v) - rest).norm(), 1e-12 * rest.norm());
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
  const Eigen::VectorXd v = uniform_random_vector(map.size(), 11);
  const Eigen::VectorXd w = uniform_random_vector(map.size(), 12);
  const double vcw = v.dot(apply_correction(c, map, w));
  EXPECT_NEAR(vcw, w.dot(apply_correction(c, map, v)), 1e-12 * std::abs(vcw));
  EXPECT_GT(v.dot(apply_correction(c, map, v)), 0.0);
  EXPECT_GT(w.dot(apply_correction(c, map, w)), 0.0);
  // It reads the lattice through the map it is given: one with other free coordinates is refused.
  sys.set_constraints(faces_held(l, {lat::Face::bottom}));
  const mess::DofMap other(sys.constraints(), l.positions, l.element_length);
  Eigen::VectorXd out = Eigen::VectorXd::Zero(other.size());
  EXPECT_THROW(c.add_to(other, uniform_random_vector(other.size(), 13), out),
               std::invalid_argument);
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
  const Eigen::VectorXd v = uniform_random_vector(map.size(), 5);
  const Eigen::VectorXd one = apply_correction(c, map, v);
  for (const int t : {2, 3}) {
    omp_set_num_threads(t);
    const mess::MultilevelCorrection other(l, sys.settings().elastic.volume_force_factor, map,
                                           kForceScale);
    EXPECT_EQ(apply_correction(other, map, v), one) << t << " threads";
    EXPECT_EQ(apply_correction(c, map, v), one) << t << " threads";
  }
  omp_set_num_threads(threads);
}

// The build splits each level's points over the threads along z, each thread summing the terms
// of its own band of lattice layers (multilevel_correction.hpp): at a deformed state of a box
// longer along z, with two particles, 2 and 7 threads give bitwise the one-thread
// correction (a term missing from a band, or summed twice, would change its sums).
TEST(MultilevelCorrection, ItsBuildSplitOverTheThreadsIsBitwiseTheSameAtADeformedState) {
  const mess::ModelProfile& profile = mess::model_profile("seed");
  mess::MessSystem sys =
      mess::MessSystem::make(small_lattice(profile, {20, 16, 60}, {{10, 8, 20}, {10, 8, 40}}),
                             Eigen::Vector3d::Zero(), profile);
  const lat::Lattice& l = sys.lattice();
  ASSERT_GE(l.node_count(), 20000);  // the build's threads start from 20,000 nodes
  sys.set_constraints(faces_held(l, {lat::Face::bottom, lat::Face::top}));
  const mess::DofMap map(sys.constraints(), l.positions, l.element_length);
  const Eigen::Matrix3Xd x = perturbed(l.positions, 0.1 * l.element_length, 23);
  const double factor = sys.settings().elastic.volume_force_factor;
  const int threads = omp_get_max_threads();
  omp_set_num_threads(1);
  const mess::MultilevelCorrection one_thread(l, factor, map, kForceScale, &x);
  EXPECT_GE(one_thread.levels(), 3);
  const Eigen::VectorXd v = uniform_random_vector(map.size(), 9);
  const Eigen::VectorXd one = apply_correction(one_thread, map, v);
  // The state changes it (else equal results could come from a build that ignored it).
  const mess::MultilevelCorrection at_rest(l, factor, map, kForceScale);
  EXPECT_GT((apply_correction(at_rest, map, v) - one).norm(), 1e-3 * one.norm());
  // Two threads, and seven: more parts than some levels have points along z.
  for (const int t : {2, 7}) {
    omp_set_num_threads(t);
    const mess::MultilevelCorrection other(l, factor, map, kForceScale, &x);
    omp_set_num_threads(1);
    EXPECT_EQ(apply_correction(other, map, v), one) << t << " threads";
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
  const Eigen::VectorXd v = uniform_random_vector(map.size(), 3);
  const mess::RigidParticlePreconditioner plain(sys, map, kForceScale, false);
  EXPECT_EQ(p.apply(map, v), plain.apply(map, v));
}

// The levels the default chooses for the full-size lattices: the Fig. 4.25 helix (66 x 66 x 228
// nodes) has its third level, 10 x 10 x 30 points (9,000 coordinates), solved exactly (with
// the earlier limit of 4,000 coordinates it took a fourth, 6 x 6 x 16); Fig. 4.11's lattice
// (44 x 44 x 147) is bound by the rule that the exact level holds at most 1/64 of the
// lattice's coordinates, so its 7 x 7 x 20 level stays the coarsest whatever the limit.
TEST(MultilevelCorrection, DefaultLevelsOfTheFullSizeLattices) {
  using Points = std::vector<std::array<int, 3>>;
  const Points helix = {{34, 34, 115}, {18, 18, 58}, {10, 10, 30}};
  EXPECT_EQ(mess::MultilevelCorrection::level_points(
                {66, 66, 228}, mess::MultilevelCorrection::kDefaultExactLimit),
            helix);
  const Points helix_before = {{34, 34, 115}, {18, 18, 58}, {10, 10, 30}, {6, 6, 16}};
  EXPECT_EQ(mess::MultilevelCorrection::level_points({66, 66, 228}, 4000), helix_before);
  const Points pair = {{23, 23, 74}, {12, 12, 38}, {7, 7, 20}};
  for (const Eigen::Index limit :
       {Eigen::Index{4000}, mess::MultilevelCorrection::kDefaultExactLimit,
        Eigen::Index{1} << 40}) {
    EXPECT_EQ(mess::MultilevelCorrection::level_points({44, 44, 147}, limit), pair) << limit;
  }
  EXPECT_THROW((void)mess::MultilevelCorrection::level_points({44, 44, 147}, 0),
               std::invalid_argument);
}

// A run keeps one plain preconditioner (built at rest) while the free coordinates stay, and
// builds a new one when they change (another face held) or the multilevel choice does; one with
// the multilevel correction is built anew at every request, at the system's positions.
TEST(PreconditionerCache, KeepsThePlainOneAndBuildsTheMultilevelOneAtEachState) {
  const mess::ModelProfile& profile = mess::model_profile("physical");
  mess::MessSystem sys =
      mess::MessSystem::make(small_lattice(profile, {6, 6, 6}), Eigen::Vector3d::Zero(), profile);
  const lat::Lattice& l = sys.lattice();
  sys.set_constraints(faces_held(l, {lat::Face::bottom}));
  mess::PreconditionerCache cache;
  const mess::DofMap map(sys.constraints(), l.positions, l.element_length);
  const auto first = cache.get(sys, map, kForceScale, false);
  ASSERT_EQ(first->multilevel(), nullptr);
  // Other prescribed values of the same held coordinates: the same free coordinates.
  Eigen::Matrix3Xd moved = l.positions;
  moved.row(0).array() += 0.1 * l.element_length;
  mess::BoundaryConstraints shifted = mess::BoundaryConstraints::none(l.node_count());
  shifted.fix_face(l.shape, lat::Face::bottom, moved);
  sys.set_constraints(shifted);
  const mess::DofMap same(sys.constraints(), l.positions, l.element_length);
  EXPECT_EQ(cache.get(sys, same, kForceScale, false), first);
  EXPECT_EQ(cache.builds(), 1);
  sys.set_constraints(faces_held(l, {lat::Face::bottom, lat::Face::top}));
  const mess::DofMap other(sys.constraints(), l.positions, l.element_length);
  const auto second = cache.get(sys, other, kForceScale, false);
  EXPECT_NE(second, first);
  EXPECT_EQ(cache.builds(), 2);

  // Multilevel: a new one per request, built at the current positions.
  const auto at_rest = cache.get(sys, other, kForceScale, true);
  ASSERT_NE(at_rest->multilevel(), nullptr);
  EXPECT_EQ(cache.builds(), 3);
  Eigen::Matrix3Xd x = sys.positions();
  for (Eigen::Index n = 0; n < x.cols(); ++n) {
    if (other.dof_of(n, 0) >= 0) x(0, n) += 0.1 * l.element_length * std::sin(0.7 * n);
  }
  sys.set_positions(x);
  const auto deformed = cache.get(sys, other, kForceScale, true);
  EXPECT_EQ(cache.builds(), 4);
  const mess::RigidParticlePreconditioner direct(sys, other, kForceScale, true, &x);
  const Eigen::VectorXd v = uniform_random_vector(other.size(), 4);
  EXPECT_EQ(deformed->apply(other, v), direct.apply(other, v));
  EXPECT_NE(deformed->apply(other, v), at_rest->apply(other, v));
}

// L-BFGS with the multilevel preconditioner (and, by default with it, its pairs in single
// precision) reaches the state L-BFGS reaches without it: a pair drawn together at 100 mT
// (physical profile, all faces held), both to 1e-9 k_eff l_e. So does the multilevel
// preconditioner with the pairs in double precision, and the rigid-particle one with them in
// single precision.
TEST(MultilevelCorrection, MinimiserReachesTheSameStateWithIt) {
  const auto relax = [](mess::LbfgsPreconditioner preconditioner,
                        mess::LbfgsHistoryPrecision history =
                            mess::LbfgsHistoryPrecision::automatic) {
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
    options.lbfgs_history = history;
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
  using mess::LbfgsHistoryPrecision;
  const auto [with_double, with_double_iterations] =
      relax(mess::LbfgsPreconditioner::multilevel, LbfgsHistoryPrecision::double_precision);
  EXPECT_LT((with_double - without).cwiseAbs().maxCoeff(), 1e-6);
  EXPECT_NE(with_double, with);  // the single-precision pairs took another path
  const auto [without_single, without_single_iterations] =
      relax(mess::LbfgsPreconditioner::rigid_particles, LbfgsHistoryPrecision::single_precision);
  EXPECT_LT((without_single - without).cwiseAbs().maxCoeff(), 1e-6);
  EXPECT_NE(without_single, without);
  EXPECT_GT(with_double_iterations + without_single_iterations, 0);
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
