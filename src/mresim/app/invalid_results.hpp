#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>
#include <string_view>

namespace mresim::app {

// Thrown by RunPlan::execute *after* it has written every result, when some of them must not be
// taken as valid: non-finite numbers, states that did not converge, fits that have too few
// points. The results stay on disk with the bad entries marked (NaN, a `valid`/`converged`
// flag of 0); `mresim run` commits the directory, prints the message as an error and exits
// with status 4 (kInvalidResults). Any other exception from execute() publishes nothing.
//
// The message says which step and quantity, e.g.
//   "non-finite results: energy at step 3 (B = 0.04 T), and 12 more (written as NaN; see
//    /steps/valid)".
struct InvalidResults : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Collects the invalid entries of one run while it writes its results and throws one
// InvalidResults naming the first few of them at the end:
//
//   ResultCheck check("non-finite results");
//   check.finite(energy, "energy", fmt::format("step {} (B = {} T)", i, b));
//   ...write everything...
//   check.throw_if_any("written as NaN; see /steps/valid in results.h5");
class ResultCheck {
 public:
  explicit ResultCheck(std::string what) : what_(std::move(what)) {}

  // Records `quantity` at `where` as invalid. Thread-unsafe: call from one thread.
  void flag(std::string_view quantity, std::string_view where);
  // Flags `value` if it is NaN or infinite; returns whether it was finite.
  bool finite(double value, std::string_view quantity, std::string_view where);

  [[nodiscard]] std::size_t count() const { return count_; }
  [[nodiscard]] bool any() const { return count_ > 0; }
  // The one-line message ("<what>: <first few entries>, and N more (<hint>)").
  [[nodiscard]] std::string message(std::string_view hint) const;
  // Throws InvalidResults(message(hint)) if anything was flagged.
  void throw_if_any(std::string_view hint) const;

 private:
  static constexpr std::size_t kListed = 3;  // entries named in the message
  std::string what_;
  std::string listed_;
  std::size_t count_ = 0;
};

}  // namespace mresim::app
