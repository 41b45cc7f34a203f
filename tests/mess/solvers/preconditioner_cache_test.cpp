// The preconditioner cache's reuse of the multilevel preconditioner (solvers/preconditioner_cache
// .hpp; solver.preconditioner_reuse): it keeps the one built at an earlier state while no node
// has moved further than the reuse distance and the same particles are in contact, builds it at
// the anchor's positions rounded to single precision, and a cache restored from the anchor
// hands out the same operator, bit for bit; with distance 0 it builds at every request.

#include "mresim/mess/solvers/preconditioner_cache.hpp"

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <memory>

#include "../support/contact_pair.hpp"
#include "../support/multilevel_test_support.hpp"
#include "mresim/mess/solvers/preconditioner.hpp"

namespace mess = mresim::mess;
using mess::testing::ContactPair;
using mess::testing::uniform_random_vector;

namespace {

constexpr double kCacheForceScale = 1e-9;  // N: any positive scale
constexpr double kCacheReuse = 0.1;        // lattice spacings

std::shared_ptr<const mess::RigidParticlePreconditioner> cached(mess::PreconditionerCache& cache,
                                                                const ContactPair& pair,
                                                                double reuse = kCacheReuse) {
  return cache.get(pair.sys, *pair.map, kCacheForceScale, true, nullptr, mess::NodeScaling::blocks,
                   mess::ContactGap::exact, reuse);
}

// Every node's z scaled by `factor` about the pair's midpoint: the pair's centres come
// `factor` times as close, the lattice compressed evenly (its gap block stays definite).
void compress_along_z(ContactPair& pair, double factor) {
  const Eigen::Matrix3Xd centres = pair.sys.particle_centres(mess::CentreRule::all_nodes);
  const double mid = 0.5 * (centres(2, 0) + centres(2, 1));
  Eigen::Matrix3Xd x = pair.sys.positions();
  x.row(2).array() = mid + (x.row(2).array() - mid) * factor;
  pair.sys.set_positions(x);
}

// Moves one polymer node with free coordinates (the first one found) by `shift` (m).
void move_one_polymer_node(ContactPair& pair, const Eigen::Vector3d& shift) {
  Eigen::Matrix3Xd x = pair.sys.positions();
  const auto& particle_of = pair.sys.lattice().particle_of_node;
  for (Eigen::Index n = 0; n < x.cols(); ++n) {
    if (particle_of[static_cast<std::size_t>(n)] < 0 && pair.map->dof_of(n, 0) >= 0 &&
        pair.map->dof_of(n, 1) >= 0 && pair.map->dof_of(n, 2) >= 0) {
      x.col(n) += shift;
      break;
    }
  }
  pair.sys.set_positions(x);
}

}  // namespace

TEST(PreconditionerCache, KeepsTheMultilevelOneWhileNoNodeMovesFurtherThanTheDistance) {
  ContactPair pair(6);  // in contact: the preconditioner holds a gap
  const double l_e = pair.sys.lattice().element_length;
  mess::PreconditionerCache cache;
  const auto first = cached(cache, pair);
  EXPECT_FALSE(cache.last_kept());
  ASSERT_NE(first->contact_gaps(), nullptr);
  ASSERT_NE(cache.anchor(), nullptr);
  EXPECT_TRUE(cache.anchor()->positions == pair.sys.positions().cast<float>());

  pair.perturb();  // every free coordinate by up to 0.05 l_e: at most 0.087 l_e per node
  EXPECT_EQ(cached(cache, pair), first);
  EXPECT_TRUE(cache.last_kept());
  EXPECT_EQ(cache.builds(), 1);

  move_one_polymer_node(pair, Eigen::Vector3d(0.0, 0.0, 0.2 * l_e));  // one node past 0.1 l_e
  const auto second = cached(cache, pair);
  EXPECT_NE(second, first);
  EXPECT_FALSE(cache.last_kept());
  EXPECT_EQ(cache.builds(), 2);
  EXPECT_TRUE(cache.anchor()->positions == pair.sys.positions().cast<float>());

  // Distance 0: built at every request, at the exact positions, with no anchor.
  EXPECT_NE(cached(cache, pair, 0.0), second);
  EXPECT_EQ(cached(cache, pair, 0.0)->contact_gaps()->gaps(), 1U);
  EXPECT_EQ(cache.builds(), 4);
  EXPECT_EQ(cache.anchor(), nullptr);
}

TEST(PreconditionerCache, RebuildsWhenAPairComesIntoContact) {
  ContactPair pair(8);  // centres 8 l_e = 3.2 R apart: no gap
  const Eigen::Matrix3Xd rest = pair.sys.positions();
  mess::PreconditionerCache cache;
  const auto apart = cached(cache, pair, 1.0);
  EXPECT_EQ(apart->contact_gaps(), nullptr);
  compress_along_z(pair, 7.7 / 8.0);  // nodes move by up to 0.375 l_e; still apart
  EXPECT_EQ(cached(cache, pair, 1.0), apart);
  EXPECT_TRUE(cache.last_kept());
  pair.sys.set_positions(rest);
  compress_along_z(pair, 7.4 / 8.0);  // 7.4 l_e < 3 R = 7.5 l_e; up to 0.75 l_e
  const auto in_contact = cached(cache, pair, 1.0);
  EXPECT_NE(in_contact, apart);
  EXPECT_FALSE(cache.last_kept());
  ASSERT_NE(in_contact->contact_gaps(), nullptr);
  EXPECT_EQ(in_contact->contact_gaps()->gaps(), 1U);
}

TEST(PreconditionerCache, BuildsAtTheAnchorAndARestoredCacheHandsOutTheSameOperator) {
  ContactPair pair(6);
  pair.perturb();
  const Eigen::Matrix3Xd start = pair.sys.positions();
  const Eigen::VectorXd v = uniform_random_vector(pair.map->size(), 5);

  mess::PreconditionerCache cache;
  const auto built = cached(cache, pair);
  // The same as a preconditioner built directly at the positions rounded to single precision,
  // bit for bit, and not the same as one built at the exact positions.
  const Eigen::Matrix3Xd rounded = start.cast<float>().cast<double>();
  const mess::RigidParticlePreconditioner at_rounded(pair.sys, *pair.map, kCacheForceScale, true,
                                                     &rounded);
  const mess::RigidParticlePreconditioner at_exact(pair.sys, *pair.map, kCacheForceScale, true,
                                                   &start);
  const Eigen::VectorXd w = built->apply(*pair.map, v);
  EXPECT_TRUE(w == at_rounded.apply(*pair.map, v));
  EXPECT_FALSE(w == at_exact.apply(*pair.map, v));

  // A run resumed a little further on: a new cache given the anchor keeps (builds) that one.
  Eigen::Matrix3Xd later = start;
  later.array() += 0.03 * pair.sys.lattice().element_length;
  pair.sys.set_positions(later);
  mess::PreconditionerCache resumed;
  resumed.restore(pair.sys.lattice(), cache.anchor());
  const auto restored = cached(resumed, pair);
  EXPECT_TRUE(resumed.last_kept());
  EXPECT_EQ(resumed.builds(), 1);
  EXPECT_TRUE(restored->apply(*pair.map, v) == w);
  // Restored without an anchor it builds at the state instead.
  mess::PreconditionerCache fresh;
  fresh.restore(pair.sys.lattice(), nullptr);
  const auto rebuilt = cached(fresh, pair);
  EXPECT_FALSE(fresh.last_kept());
  EXPECT_FALSE(rebuilt->apply(*pair.map, v) == w);
}
