#pragma once

#include <atomic>
#include <exception>
#include <utility>

namespace mresim {

// Carries an exception out of an OpenMP parallel region.
//
// An exception that leaves a parallel region (or one iteration of a worksharing loop) calls
// std::terminate: the program aborts, and in `mresim run` the staging directory is left behind.
// Every parallel region that can throw therefore runs its body through one ParallelExceptions:
//
//   ParallelExceptions errors;
//   #pragma omp parallel for
//   for (long i = 0; i < n; ++i) {
//     errors.run([&] { work(i); });
//   }
//   errors.rethrow();  // on the calling thread, after the region
//
// The first exception (in time) is kept and rethrown after the region; once one iteration has
// failed, the iterations that have not started yet are skipped (their results would be
// discarded anyway). The others that were already running finish normally.
class ParallelExceptions {
 public:
  // Runs `body()`, capturing whatever it throws. Safe to call from any thread of the region.
  template <class Body>
  void run(Body&& body) noexcept {
    if (failed_.load(std::memory_order_relaxed)) return;
    try {
      std::forward<Body>(body)();
    } catch (...) {
      capture(std::current_exception());
    }
  }

  // Whether an exception has been captured.
  [[nodiscard]] bool failed() const noexcept { return failed_.load(std::memory_order_acquire); }

  // Rethrows the first captured exception, if any. Call after the parallel region.
  void rethrow() const {
    if (first_) std::rethrow_exception(first_);
  }

 private:
  void capture(std::exception_ptr e) noexcept {
#pragma omp critical(mresim_parallel_exceptions)
    {
      if (!first_) first_ = std::move(e);
    }
    failed_.store(true, std::memory_order_release);
  }

  std::exception_ptr first_;
  std::atomic<bool> failed_{false};
};

}  // namespace mresim
