// use_one_allocator_arena (app/allocator_arenas.hpp): a thread started after it allocates from an
// arena that already exists instead of creating one of its own. glibc's malloc_info lists one
// <heap> element per arena, so the count must not grow; without the limit a new thread's first
// allocation adds one.

#include "mresim/app/allocator_arenas.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

// AddressSanitizer replaces malloc with its own allocator, which has no arenas to limit (its
// mallopt does nothing and reports failure).
#if defined(__SANITIZE_ADDRESS__)
#define MRESIM_ALLOCATOR_REPLACED 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define MRESIM_ALLOCATOR_REPLACED 1
#endif
#endif

namespace mresim::app {
namespace {

#if defined(__GLIBC__)
int allocator_arena_count() {
  char* text = nullptr;
  std::size_t size = 0;
  FILE* stream = open_memstream(&text, &size);
  if (stream == nullptr) return -1;
  malloc_info(0, stream);
  std::fclose(stream);
  const std::string info(text, size);
  std::free(text);
  int count = 0;
  for (std::size_t at = info.find("<heap nr="); at != std::string::npos;
       at = info.find("<heap nr=", at + 1)) {
    ++count;
  }
  return count;
}

TEST(AllocatorArenas, AThreadStartedAfterwardsCreatesNoArena) {
#if defined(MRESIM_ALLOCATOR_REPLACED)
  GTEST_SKIP() << "AddressSanitizer's allocator replaces glibc's malloc arenas";
#endif
  ASSERT_TRUE(use_one_allocator_arena());
  const int before = allocator_arena_count();
  ASSERT_GE(before, 1);
  int during = 0;
  std::thread worker([&during] {
    // Below glibc's mmap threshold, so that it comes from an arena.
    void* block = std::malloc(4096);
    ASSERT_NE(block, nullptr);
    during = allocator_arena_count();
    std::free(block);
  });
  worker.join();
  EXPECT_EQ(during, before);
}
#endif

}  // namespace
}  // namespace mresim::app
