#include "mresim/app/allocator_arenas.hpp"

#include <cstdlib>  // defines __GLIBC__ (through <features.h>) where the C library is glibc

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace mresim::app {

bool use_one_allocator_arena() {
#if defined(__GLIBC__)
  return mallopt(M_ARENA_MAX, 1) == 1;  // mallopt returns 1 on success
#else
  return false;
#endif
}

}  // namespace mresim::app
