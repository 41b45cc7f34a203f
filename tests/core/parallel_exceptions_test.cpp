// An exception thrown inside an OpenMP parallel loop reaches the caller (instead of calling
// std::terminate) through mresim::ParallelExceptions.
#include "mresim/core/parallel_exceptions.hpp"

#include <gtest/gtest.h>
#include <omp.h>

#include <atomic>
#include <stdexcept>
#include <vector>

namespace {

TEST(ParallelExceptions, RethrowsAnExceptionThrownInsideAParallelLoop) {
  mresim::ParallelExceptions errors;
  std::atomic<int> ran{0};
#pragma omp parallel for schedule(dynamic, 1) num_threads(4)
  for (long i = 0; i < 1000; ++i) {
    errors.run([&] {
      ++ran;
      if (i == 17) throw std::invalid_argument("iteration 17 failed");
    });
  }
  EXPECT_TRUE(errors.failed());
  EXPECT_GE(ran.load(), 1);
  try {
    errors.rethrow();
    FAIL() << "no exception rethrown";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "iteration 17 failed");
  }
}

TEST(ParallelExceptions, KeepsOneOfSeveralAndSkipsLaterIterations) {
  mresim::ParallelExceptions errors;
  std::atomic<int> ran{0};
#pragma omp parallel for schedule(static, 1) num_threads(2)
  for (long i = 0; i < 100; ++i) {
    errors.run([&] {
      ++ran;
      throw std::runtime_error("failed");
    });
  }
  EXPECT_THROW(errors.rethrow(), std::runtime_error);
  EXPECT_LT(ran.load(), 100);  // iterations after the first failure are skipped
}

TEST(ParallelExceptions, DoesNothingWithoutAnException) {
  mresim::ParallelExceptions errors;
  std::vector<int> out(64, 0);
#pragma omp parallel for
  for (long i = 0; i < 64; ++i) {
    errors.run([&] { out[static_cast<std::size_t>(i)] = 1; });
  }
  EXPECT_FALSE(errors.failed());
  EXPECT_NO_THROW(errors.rethrow());
  for (const int v : out) EXPECT_EQ(v, 1);
}

}  // namespace
