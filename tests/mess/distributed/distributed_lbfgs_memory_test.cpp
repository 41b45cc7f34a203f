// L-BFGS's memory split over MPI processes (LbfgsMemory::set_split, MpiBlockSplit, docs/mpi.md):
// each process stores only its own blocks of the pairs, and the product is still bitwise the
// single-process one on every process, in L-BFGS's order of products and adds and out of it.
// Vectors of several kSumBlock blocks with a short last block, and a preconditioner that mixes
// entries of different processes' blocks. Run on one process by ctest and on two and three in
// mess_distributed_two_ranks/_three_ranks, where with three processes one owns a single block.

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <memory>
#include <random>

#include "mpi_test_support.hpp"
#include "mresim/mess/distributed/mpi_block_split.hpp"
#include "mresim/mess/solvers/lbfgs_memory.hpp"
#include "mresim/mess/system/fixed_order.hpp"

namespace mess = mresim::mess;
using mess::detail::kSumBlock;
using mess::detail::LbfgsMemory;
using mess::testing::everywhere;
using mess::testing::world_size;

namespace {

// The same pseudo-random vector on every process.
Eigen::VectorXd random_vector(Eigen::Index n, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::VectorXd v(n);
  for (Eigen::Index i = 0; i < n; ++i) v[i] = u(rng);
  return v;
}

// P v = w .* v + 0.3 (v reversed): each entry depends on one at the other end of the vector,
// which another process owns. Symmetric positive definite (w >= 1).
LbfgsMemory::Preconditioner mixing_preconditioner(const Eigen::VectorXd& w) {
  return [w](const Eigen::VectorXd& v) -> Eigen::VectorXd {
    return w.cwiseProduct(v) + 0.3 * v.reverse();
  };
}

}  // namespace

// With the pairs stored in `precision`.
void expect_split_product_is_the_whole_one(mess::detail::LbfgsPrecision precision) {
  SCOPED_TRACE(precision == mess::detail::LbfgsPrecision::single_precision ? "single precision"
                                                                           : "double precision");
  const Eigen::Index n = 3 * kSumBlock + 1234;  // four blocks, the last one short
  std::mt19937_64 rng(7);
  const Eigen::VectorXd curvature = 1.0 + random_vector(n, rng).array().abs();
  const Eigen::VectorXd w = 1.0 + random_vector(n, rng).array().abs();
  const LbfgsMemory::Preconditioner P = mixing_preconditioner(w);

  LbfgsMemory whole;
  LbfgsMemory split;
  whole.set_precision(precision);
  split.set_precision(precision);
  split.set_split(std::make_shared<mess::MpiBlockSplit>(MPI_COMM_WORLD));
  constexpr int kCapacity = 3;
  // L-BFGS's order (each pair's P y from two products' P g) and, every other pair, a product
  // at another point (the pair's P y formed by applying P to its y, which each process holds
  // only in part).
  Eigen::VectorXd g_old = random_vector(n, rng);
  ASSERT_TRUE(everywhere(split.times(g_old, P) == whole.times(g_old, P)));
  for (int pair = 0; pair < 6; ++pair) {  // more pairs than the capacity: storage is reused
    const Eigen::VectorXd d = random_vector(n, rng);
    const double alpha = 0.5 + 0.1 * pair;
    const Eigen::VectorXd g_new = g_old + curvature.cwiseProduct(alpha * d);
    whole.add(alpha, d, g_new, g_old, kCapacity);
    split.add(alpha, d, g_new, g_old, kCapacity);
    ASSERT_TRUE(everywhere(whole.size() == split.size()));
    const Eigen::VectorXd g = pair % 2 == 0 ? g_new : Eigen::VectorXd(random_vector(n, rng));
    const Eigen::VectorXd expected = whole.times(g, P);
    const Eigen::VectorXd product = split.times(g, P);
    EXPECT_TRUE(everywhere(product == expected))
        << "pair " << pair << ": largest difference " << (product - expected).cwiseAbs().maxCoeff();
    g_old = g;
  }
  EXPECT_EQ(whole.size(), kCapacity);

  // After preconditioner_changed() (a new preconditioner) the pairs are gone and the product
  // is P g on every process.
  const LbfgsMemory::Preconditioner P2 = mixing_preconditioner(2.0 * w);
  whole.preconditioner_changed();
  split.preconditioner_changed();
  const Eigen::VectorXd g = random_vector(n, rng);
  EXPECT_TRUE(everywhere(split.times(g, P2) == P2(g)));
  EXPECT_TRUE(everywhere(whole.times(g, P2) == P2(g)));
  // Pairs again, for the stored entries below.
  for (int pair = 0; pair < kCapacity; ++pair) {
    const Eigen::VectorXd d = random_vector(n, rng);
    const Eigen::VectorXd g_new = g_old + curvature.cwiseProduct(d);
    whole.add(1.0, d, g_new, g_old, kCapacity);
    split.add(1.0, d, g_new, g_old, kCapacity);
    g_old = g_new;
  }

  // Each process stores only its blocks: together exactly the whole memory once.
  long long mine = split.stored_entries();
  long long total = 0;
  MPI_Allreduce(&mine, &total, 1, MPI_LONG_LONG, MPI_SUM, MPI_COMM_WORLD);
  EXPECT_EQ(total, static_cast<long long>(whole.stored_entries()));
  EXPECT_EQ(whole.stored_entries(), 2 * kCapacity * n);
  if (world_size() > 1) {
    EXPECT_TRUE(everywhere(mine <= 2 * kCapacity * 2 * kSumBlock)) << mine;
  }
}

TEST(DistributedLbfgsMemory, ProductIsBitwiseTheSingleProcessOne) {
  expect_split_product_is_the_whole_one(mess::detail::LbfgsPrecision::double_precision);
  expect_split_product_is_the_whole_one(mess::detail::LbfgsPrecision::single_precision);
}

TEST(DistributedLbfgsMemory, BlocksAreDealtOutWholeAndInOrder) {
  const mess::MpiBlockSplit split(MPI_COMM_WORLD);
  const int size = world_size();
  for (const Eigen::Index n : {Eigen::Index{0}, Eigen::Index{5}, kSumBlock, 3 * kSumBlock + 1}) {
    const auto o = split.owned(n);
    // Each process starts at the block where the one before it ends; the first starts at
    // block 0, the last ends at the last block (received by the first, from the ring).
    long long last = o.last_block;
    long long previous_last = 0;
    MPI_Sendrecv(&last, 1, MPI_LONG_LONG, (mess::testing::world_rank() + 1) % size, 0,
                 &previous_last, 1, MPI_LONG_LONG, (mess::testing::world_rank() + size - 1) % size,
                 0, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    const long long blocks = (n + kSumBlock - 1) / kSumBlock;
    if (mess::testing::world_rank() == 0) {
      EXPECT_EQ(o.first_block, 0);
      EXPECT_EQ(previous_last, blocks) << "the last process ends at the last block";
    } else {
      EXPECT_EQ(o.first_block, previous_last);
    }
    EXPECT_EQ(o.begin, std::min<Eigen::Index>(n, o.first_block * kSumBlock));
    EXPECT_EQ(o.end, std::min<Eigen::Index>(n, o.last_block * kSumBlock));
  }
}
