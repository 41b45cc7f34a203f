// A tiny run type that exists only in test builds (mresim_tests and the mresim_testbed
// executable), so the registry, `mresim run` and `mresim info` can be tested end to end without
// depending on any physics module.
//
//   [run]
//   type = "test_dummy"
//   [dummy]
//   steps = 4         # integer >= 1
//   scale = 0.5       # m, > 0 (default 1)
//   fail_at = 2       # optional: throw at this step, to test cleanup
//   nan_at = 1        # optional: this step's value is NaN (invalid results, exit status 4)
//   step_seconds = 0.2  # optional: sleep this long per step (locks, signals)
//   own_safe_points = true        # optional: the plan says it stops at safe points of its own
//                                 # (RunPlan::stops_at_own_safe_points), as the 3D run types do
//   signal_after_last_step = true # optional: raise SIGINT in this process after the last step

#include <omp.h>

#include <chrono>
#include <csignal>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <thread>

#include "mresim/app/invalid_results.hpp"
#include "mresim/app/run_type.hpp"
#include "mresim/io/csv_writer.hpp"

namespace {

using mresim::config::Range;

class DummyPlan final : public mresim::app::RunPlan {
 public:
  explicit DummyPlan(const mresim::config::TableReader& root) {
    const auto dummy = root.table("dummy");
    steps_ = dummy.integer("steps", Range::at_least(1));
    scale_ = dummy.number_or("scale", 1.0, Range::positive(), "m");
    fail_at_ = dummy.integer_or("fail_at", -1, Range::any());
    nan_at_ = dummy.integer_or("nan_at", -1, Range::any());
    step_seconds_ = dummy.number_or("step_seconds", 0.0, Range::between(0.0, 60.0), "s");
    own_safe_points_ = dummy.boolean_or("own_safe_points", false);
    signal_after_last_step_ = dummy.boolean_or("signal_after_last_step", false);
  }

  [[nodiscard]] bool stops_at_own_safe_points() const override { return own_safe_points_; }

  void describe(mresim::app::InfoReport& report) const override {
    report.add_integer("dummy", "steps", steps_);
    report.add("dummy", "scale", scale_, "m", "length of one step");
    report.add("dummy", "total_length", scale_ * static_cast<double>(steps_), "m");
  }

  void execute(const std::filesystem::path& staging_dir, mresim::io::Hdf5File& results,
               mresim::app::Progress& progress) const override {
    progress.set_total(static_cast<std::size_t>(steps_));
    std::vector<double> values;
    mresim::io::CsvWriter csv(staging_dir / "summary.csv", {"step", "value_m"});
    mresim::app::ResultCheck check("non-finite results");
    for (long i = 0; i < steps_; ++i) {
      if (i == fail_at_) throw std::runtime_error("dummy failure at step " + std::to_string(i));
      std::this_thread::sleep_for(std::chrono::duration<double>(step_seconds_));
      values.push_back(i == nan_at_ ? std::numeric_limits<double>::quiet_NaN()
                                    : scale_ * static_cast<double>(i));
      check.finite(values.back(), "value", "step " + std::to_string(i));
      csv.row({static_cast<double>(i), values.back()});
      progress.advance();
    }
    if (signal_after_last_step_) (void)std::raise(SIGINT);  // as a Ctrl-C during the writes
    csv.close();
    results.write_vector("/dummy/values", values, "m");
    results.write_int_attribute("/dummy", "threads", omp_get_max_threads());
    check.throw_if_any("written as NaN");
  }

 private:
  long steps_ = 0;
  double scale_ = 1.0;
  long fail_at_ = -1;
  long nan_at_ = -1;
  double step_seconds_ = 0.0;
  bool own_safe_points_ = false;
  bool signal_after_last_step_ = false;
};

const mresim::app::RunTypeRegistrar dummy_run_type_registrar(
    {"test_dummy", "Test-only run type",
     [](const mresim::config::TableReader& root) { return std::make_unique<DummyPlan>(root); }});

}  // namespace
