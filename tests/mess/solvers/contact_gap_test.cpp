// The gap blocks of the minimisers' preconditioner (solvers/contact_gap_blocks.hpp;
// solver.contact_gap): only a pair of particles less than three radii apart has one; what they
// add to P is the exact inverse of the elastic Hessian's block of the gap's coordinates (that
// block assembled here independently, from MessSystem::elastic_hessian); P stays symmetric
// positive definite and bitwise the same on every thread count; and the minimiser with the
// multilevel preconditioner reaches the same state with or without them.

#include <gtest/gtest.h>
#include <omp.h>

#include <Eigen/Dense>
#include <Eigen/SparseCore>
#include <cmath>
#include <memory>
#include <utility>
#include <vector>

#include "../support/contact_pair.hpp"
#include "../support/mess_test_support.hpp"
#include "../support/multilevel_test_support.hpp"
#include "../support/small_runs.hpp"
#include "mresim/mess/solvers/contact_gap_blocks.hpp"
#include "mresim/mess/solvers/minimiser.hpp"
#include "mresim/mess/solvers/preconditioner.hpp"

namespace mess = mresim::mess;
namespace lat = mresim::lattice;
using mess::testing::faces_held;
using mess::testing::small_lattice;
using mess::testing::tesla;
using mess::testing::uniform_random_vector;

namespace {

constexpr double kGapForceScale = 1e-9;  // N: any positive scale

using Pair = mess::testing::ContactPair;

TEST(ContactGap, OnlyAPairLessThanThreeRadiiApartHasAGap) {
  const Pair close(6);  // 6 l_e = 2.4 R
  const Pair far(8);    // 8 l_e = 3.2 R
  const mess::ContactGapBlocks in_contact(close.sys, *close.map, kGapForceScale,
                                          close.sys.positions());
  const mess::ContactGapBlocks apart(far.sys, *far.map, kGapForceScale, far.sys.positions());
  EXPECT_EQ(in_contact.gaps(), 1U);
  EXPECT_EQ(in_contact.left_out(), 0);
  EXPECT_GT(in_contact.dofs(), 300);
  EXPECT_EQ(in_contact.dofs() % 3, 0);
  EXPECT_EQ(apart.gaps(), 0U);
  // The preconditioner keeps them only where it is built at a state, and only if asked.
  const mess::RigidParticlePreconditioner at_state(close.sys, *close.map, kGapForceScale, true,
                                                   &close.sys.positions());
  const mess::RigidParticlePreconditioner at_rest(close.sys, *close.map, kGapForceScale, true);
  const mess::RigidParticlePreconditioner none(close.sys, *close.map, kGapForceScale, true,
                                               &close.sys.positions(), nullptr,
                                               mess::NodeScaling::blocks, mess::ContactGap::none);
  ASSERT_NE(at_state.contact_gaps(), nullptr);
  EXPECT_EQ(at_state.contact_gaps()->dofs(), in_contact.dofs());
  EXPECT_EQ(at_rest.contact_gaps(), nullptr);
  EXPECT_EQ(none.contact_gaps(), nullptr);
}

// (P - P without the gap) v lives on the gap's coordinates S, and there H_SS times it gives v_S
// back, with H_SS the elastic Hessian's block (scaled l_e / force scale), at a perturbed state.
TEST(ContactGap, AddsTheExactInverseOfTheGapsHessianBlock) {
  Pair d(6);
  d.perturb();
  const mess::DofMap& map = *d.map;
  const Eigen::Matrix3Xd& x = d.sys.positions();
  const mess::RigidParticlePreconditioner with(d.sys, map, kGapForceScale, true, &x);
  const mess::RigidParticlePreconditioner without(d.sys, map, kGapForceScale, true, &x, nullptr,
                                                  mess::NodeScaling::blocks,
                                                  mess::ContactGap::none);
  const Eigen::VectorXd v = uniform_random_vector(map.size(), 11);
  const Eigen::VectorXd added = with.apply(map, v) - without.apply(map, v);
  std::vector<Eigen::Index> support;
  for (Eigen::Index k = 0; k < added.size(); ++k) {
    if (added[k] != 0.0) support.push_back(k);
  }
  ASSERT_EQ(static_cast<Eigen::Index>(support.size()), with.contact_gaps()->dofs());

  const double scale = d.sys.lattice().element_length / kGapForceScale;
  const auto m = static_cast<Eigen::Index>(support.size());
  const auto gap_block = [&](const mess::MessSystem& sys) {
    const Eigen::SparseMatrix<double> h = sys.elastic_hessian();
    Eigen::MatrixXd block(m, m);
    for (Eigen::Index r = 0; r < m; ++r) {
      for (Eigen::Index c = 0; c < m; ++c) {
        block(r, c) = scale * h.coeff(map.coordinate_of(support[static_cast<std::size_t>(r)]),
                                      map.coordinate_of(support[static_cast<std::size_t>(c)]));
      }
    }
    return block;
  };
  const Eigen::MatrixXd block = gap_block(d.sys);
  mess::MessSystem at_rest = d.sys;
  at_rest.set_positions(d.sys.lattice().positions);
  const Eigen::MatrixXd rest_block = gap_block(at_rest);
  Eigen::VectorXd on_gap(m);
  Eigen::VectorXd v_gap(m);
  for (Eigen::Index r = 0; r < m; ++r) {
    on_gap[r] = added[support[static_cast<std::size_t>(r)]];
    v_gap[r] = v[support[static_cast<std::size_t>(r)]];
  }
  // The factor is kept in single precision (contact_gap_blocks.hpp).
  EXPECT_LT((block * on_gap - v_gap).norm(), 1e-5 * v_gap.norm());
  // The block of this state, not of the rest lattice (the check can tell them apart).
  EXPECT_GT((rest_block * on_gap - v_gap).norm(), 1e-3 * v_gap.norm());
}

TEST(ContactGap, KeepsPSymmetricPositiveDefiniteAndThreadIndependent) {
  Pair d(6);
  d.perturb();
  const mess::DofMap& map = *d.map;
  const mess::RigidParticlePreconditioner p(d.sys, map, kGapForceScale, true, &d.sys.positions());
  ASSERT_NE(p.contact_gaps(), nullptr);
  const Eigen::VectorXd u = uniform_random_vector(map.size(), 12);
  const Eigen::VectorXd v = uniform_random_vector(map.size(), 13);
  const Eigen::VectorXd pu = p.apply(map, u);
  const Eigen::VectorXd pv = p.apply(map, v);
  EXPECT_NEAR(u.dot(pv), v.dot(pu), 1e-10 * std::sqrt(u.dot(pu) * v.dot(pv)));
  EXPECT_GT(u.dot(pu), 0.0);
  EXPECT_GT(v.dot(pv), 0.0);
  const int threads = omp_get_max_threads();
  for (const int t : {1, 2, 3}) {
    omp_set_num_threads(t);
    EXPECT_EQ(p.apply(map, v), pv) << t << " threads";
  }
  omp_set_num_threads(threads);
}

// Three particles in a chain, 6 l_e apart: two pairs in contact, two gaps, built one per
// thread where there are threads; each gap (its coordinates and its factor) is the same for
// any number of threads.
TEST(ContactGap, SeveralGapsAreTheSameOnEveryThreadCount) {
  mess::MessSystem sys =
      mess::MessSystem::make(small_lattice(mess::model_profile("physical"), {12, 12, 26},
                                           {{6, 6, 7}, {6, 6, 13}, {6, 6, 19}}, 2),
                             tesla(0.0, 0.0, 0.0), mess::model_profile("physical"));
  sys.set_constraints(
      faces_held(sys.lattice(), {lat::Face::left, lat::Face::right, lat::Face::front,
                                 lat::Face::back, lat::Face::bottom, lat::Face::top}));
  const mess::DofMap map(sys.constraints(), sys.lattice().positions, sys.lattice().element_length);
  const int threads = omp_get_max_threads();
  omp_set_num_threads(1);
  const mess::ContactGapBlocks one(sys, map, kGapForceScale, sys.positions());
  omp_set_num_threads(2);
  const mess::ContactGapBlocks two(sys, map, kGapForceScale, sys.positions());
  omp_set_num_threads(threads);
  ASSERT_EQ(one.gaps(), 2U);
  ASSERT_EQ(two.gaps(), 2U);
  EXPECT_EQ(one.dofs(), two.dofs());
  for (std::size_t g = 0; g < 2; ++g) {
    const Eigen::SparseMatrix<float>& a = one.factor(g).matrixL().nestedExpression();
    const Eigen::SparseMatrix<float>& b = two.factor(g).matrixL().nestedExpression();
    ASSERT_EQ(a.nonZeros(), b.nonZeros()) << g;
    EXPECT_EQ(Eigen::Map<const Eigen::VectorXf>(a.valuePtr(), a.nonZeros()),
              Eigen::Map<const Eigen::VectorXf>(b.valuePtr(), b.nonZeros()))
        << g;
  }
  const Eigen::VectorXd v = uniform_random_vector(map.size(), 14);
  Eigen::VectorXd w_one = Eigen::VectorXd::Zero(map.size());
  Eigen::VectorXd w_two = Eigen::VectorXd::Zero(map.size());
  one.add_to(v, w_one);
  two.add_to(v, w_two);
  EXPECT_EQ(w_one, w_two);
  EXPECT_GT(w_one.norm(), 0.0);
}

// L-BFGS with the multilevel preconditioner: a pair 6 l_e apart drawn together at 100 mT
// (physical profile), to 1e-9 k_eff l_e, reaches the same state with and without the gap.
TEST(ContactGap, MinimiserReachesTheSameStateWithOrWithoutTheGap) {
  const auto relax = [](mess::ContactGap gap) {
    Pair d(6, 0.1);
    d.sys.settings().magnetization.atol = 1e-11;
    d.sys.settings().magnetization.rtol = 1e-11;
    mess::MinimiserOptions options;
    options.force_tolerance = 1e-9;
    options.lbfgs_preconditioner = mess::LbfgsPreconditioner::multilevel;
    options.contact_gap = gap;
    const mess::MinimiserResult r = mess::minimise(d.sys, options);
    EXPECT_TRUE(r.converged) << mess::to_string(r.status);
    return std::pair{Eigen::Matrix3Xd(d.sys.positions() / d.sys.lattice().element_length),
                     r.iterations};
  };
  const auto [exact, exact_iterations] = relax(mess::ContactGap::exact);
  const auto [none, none_iterations] = relax(mess::ContactGap::none);
  EXPECT_LT((exact - none).cwiseAbs().maxCoeff(), 1e-6);
  EXPECT_NE(exact, none);  // the two took different paths: the setting reached P
  EXPECT_GT(exact_iterations, 0);
  EXPECT_GT(none_iterations, 0);
}

// solver.contact_gap: "exact" by default, and "none" read.
TEST(ContactGap, RunFilesChooseIt) {
  namespace mc = mresim::mess_config;
  namespace mp = mresim::mess_protocol;
  const std::string toml = mp::testing::small_hysteresis(0.03, 3);
  EXPECT_EQ(mp::testing::spec_of(toml).solver.contact_gap, mess::ContactGap::exact);
  const mc::MessSpec none = mp::testing::spec_of(toml + "\n[solver]\ncontact_gap = \"none\"\n");
  EXPECT_EQ(none.solver.contact_gap, mess::ContactGap::none);
}

}  // namespace
