// Run type "preisach": the hysteresis loop of a magnetically hard ferromagnet from the classical
// Preisach model with rectangular relays (Fig. 1.5, ref. [37]).
//
//   [preisach]  relays = 100000, switch_up_mean = 0.35 (T), switch_down_mean = -0.35 (T),
//               switch_sd = 0.2 (T), weight_mean = 5, weight_sd = 2.5, weight_min = 0.01,
//               seed = 1
//   [field]     max = 1.0 (T), step = 0.01 (T)
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>

#include "mresim/app/run_type.hpp"
#include "mresim/magnetism/preisach.hpp"
#include "mresim/magnetism/runs/curve_outputs.hpp"
#include "mresim/magnetism/runs/preisach_expectation.hpp"

namespace mresim::magnetism::runs {
namespace {

using config::Range;

// 1e8 relays already take ~2.5 GB (alpha, beta, weight, state); PreisachParameters holds an int.
constexpr double kMaxRelays = 1e8;

class PreisachPlan final : public app::RunPlan {
 public:
  explicit PreisachPlan(const config::TableReader& root) {
    // Defaults are the Fig. 1.5 caption values (PreisachParameters{}).
    if (const auto t = root.optional_table("preisach")) {
      PreisachParameters& p = params_;
      p.relay_count =
          static_cast<int>(t->integer_or("relays", p.relay_count, Range::between(1.0, kMaxRelays)));
      p.switch_up_mean_t = t->number_or("switch_up_mean", p.switch_up_mean_t, Range::any(), "T");
      p.switch_down_mean_t =
          t->number_or("switch_down_mean", p.switch_down_mean_t, Range::any(), "T");
      p.switch_sd_t = t->number_or("switch_sd", p.switch_sd_t, Range::positive(), "T");
      p.weight_mean = t->number_or("weight_mean", p.weight_mean, Range::positive(), "");
      p.weight_sd = t->number_or("weight_sd", p.weight_sd, Range::non_negative(), "");
      p.weight_min = t->number_or("weight_min", p.weight_min, Range::positive(), "");
      p.seed = static_cast<std::uint64_t>(
          t->integer_or("seed", static_cast<long>(p.seed), Range::non_negative()));
    }
    sweep_ = read_field_sweep(root, 1.0);
  }

  void describe(app::InfoReport& report) const override {
    const PreisachParameters& p = params_;
    report.add_integer("preisach", "relays", p.relay_count);
    report.add("preisach", "switch_up_mean", p.switch_up_mean_t, "T", "mean of alpha");
    report.add("preisach", "switch_down_mean", p.switch_down_mean_t, "T", "mean of beta");
    report.add("preisach", "switch_sd", p.switch_sd_t, "T", "sd of alpha and beta");
    report.add("preisach", "weight_mean", p.weight_mean, "");
    report.add("preisach", "weight_sd", p.weight_sd, "");
    report.add("preisach", "weight_min", p.weight_min, "", "weights clipped up to this");
    report.add_integer("preisach", "seed", static_cast<std::int64_t>(p.seed));
    describe_field(report, sweep_);
    // Expectations for an infinite population (preisach_expectation.hpp); the simulated values
    // scatter around them by ~1/sqrt(relays).
    report.add("derived", "expected_coercive_field", expected_coercive_field(p), "T",
               "zero of 1 - 2 P(a >= B) P(b >= B)");
    report.add("derived", "expected_remanence", expected_remanence(p), "",
               "M_r/Ms = 1 - 2 P(a >= 0) P(b >= 0)");
    report.add("derived", "expected_up_fraction_at_field_max",
               expected_up_fraction(p, sweep_.max_t), "",
               "P(alpha <= max); the expectations assume ~1 (saturation)");
    report.add("derived", "sampling_noise", 1.0 / std::sqrt(p.relay_count), "",
               "~1/sqrt(relays), scale of M/Ms scatter");
    report.add("derived", "clipped_weight_fraction", clipped_weight_fraction(p), "",
               "P(weight draw < weight_min)");
  }

  void execute(const std::filesystem::path& staging_dir, io::Hdf5File& results,
               app::Progress& progress) const override {
    // preisach_loop() step by step, to report progress (1e5 relays x 751 fields at Fig. 1.5).
    const std::vector<SweepPoint> sweep = major_loop_sweep(sweep_.max_t, sweep_.grid_step_t());
    progress.set_total(sweep.size());
    PreisachModel model(params_);
    MagnetizationCurve curve;
    for (const SweepPoint& point : sweep) {
      curve.b_tesla.push_back(point.b_tesla);
      curve.m_over_ms.push_back(model.apply_field(point.b_tesla));
      curve.branch.push_back(point.branch);
      progress.advance();
    }
    // The relay model is normalized (sum of weights 1): it has no Ms in A/m.
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const app::ResultCheck check = write_curve(staging_dir, results, curve, {nan, nan});
    check.throw_if_any("written as NaN in summary.csv and /curve");
  }

 private:
  PreisachParameters params_;
  FieldSweep sweep_;
};

const app::RunTypeRegistrar preisach_run_registrar(
    {"preisach",
     "Preisach hysteresis loop of a hard ferromagnet "
     "(Fig. 1.5)",
     [](const config::TableReader& root) { return std::make_unique<PreisachPlan>(root); }});

}  // namespace
}  // namespace mresim::magnetism::runs
