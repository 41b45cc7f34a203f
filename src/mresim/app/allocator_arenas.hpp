#pragma once

// One malloc arena for the whole process (glibc). By default glibc gives each thread that
// allocates its own arena. The 3D runs allocate in their worker threads too (the multilevel
// preconditioner builds one level per thread), and memory freed into a thread's arena stays
// resident there instead of serving the main thread's next allocation: over the full-size
// Fig. 4.11 loop this kept about 20 MB (72 bytes per node) more resident than the run ever
// used at once (docs/performance.md, "One malloc arena"). The worker threads allocate rarely,
// so they seldom wait for the shared arena: the loop with one arena was not slower.

namespace mresim::app {

// Limits the process to one malloc arena. Call it first thing in main(), before any thread
// starts: threads that have already allocated keep their arenas. Returns false where the C
// library has no such setting (not glibc) or refuses it; the process then runs as before.
bool use_one_allocator_arena();

}  // namespace mresim::app
