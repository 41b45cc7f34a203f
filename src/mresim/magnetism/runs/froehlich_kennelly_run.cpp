// Run type "froehlich_kennelly": the anhysteretic magnetization curve of a magnetically soft
// particle, eq. 1.5, along a major-loop sweep (Fig. 1.6: chi0 = 70, Ms = 1.6e6 A/m).
//
//   [material]  susceptibility = 70, saturation_magnetization = 1.6e6 (A/m)
//   [field]     max = 1.0 (T), step = 0.01 (T)
#include <fmt/format.h>

#include <memory>

#include "mresim/app/run_type.hpp"
#include "mresim/core/constants.hpp"
#include "mresim/magnetism/froehlich_kennelly.hpp"
#include "mresim/magnetism/runs/curve_outputs.hpp"

namespace mresim::magnetism::runs {
namespace {

using config::Range;

constexpr double kMaxParameter = 1e60;  // bound on chi0 and on Ms (A/m)

class FroehlichKennellyPlan final : public app::RunPlan {
 public:
  explicit FroehlichKennellyPlan(const config::TableReader& root) {
    if (const auto t = root.optional_table("material")) {
      chi0_ = t->number_or("susceptibility", chi0_, Range::positive(), "");
      ms_ = t->number_or("saturation_magnetization", ms_, Range::positive(), "A/m");
      // Eq. 1.5 multiplies Ms chi0 H; with field.max <= 1e100 T (H <= 8e105 A/m) these bounds
      // keep that product below 1e226, far from overflow.
      if (chi0_ > kMaxParameter) {
        t->fail("susceptibility", chi0_,
                fmt::format("must be <= {:.0e} (eq. 1.5 multiplies chi0 H Ms, which would "
                            "overflow)",
                            kMaxParameter));
      }
      if (ms_ > kMaxParameter) {
        t->fail("saturation_magnetization", ms_,
                fmt::format("must be <= {:.0e} A/m (eq. 1.5 multiplies chi0 H Ms, which would "
                            "overflow)",
                            kMaxParameter));
      }
    }
    sweep_ = read_field_sweep(root, 1.0);
  }

  void describe(app::InfoReport& report) const override {
    report.add("material", "susceptibility", chi0_, "", "chi0, initial susceptibility");
    report.add("material", "saturation_magnetization", ms_, "A/m", "Ms");
    describe_field(report, sweep_);
    // Eq. 1.5 evaluated in closed form at the sweep's turning point (applied B = mu0 H).
    const double h_max = sweep_.max_t / kMu0;
    report.add("derived", "H_at_field_max", h_max, "A/m", "H = B_max / mu0");
    report.add("derived", "M_over_Ms_at_field_max", froehlich_kennelly(h_max, chi0_, ms_) / ms_, "",
               "eq. 1.5: chi0 H / (Ms + chi0 H)");
    // M = Ms/2 in eq. 1.5 <=> chi0 H = Ms: the field where the linear law (1.4) stops holding.
    report.add("derived", "half_saturation_H", ms_ / chi0_, "A/m", "M = Ms/2 at H = Ms / chi0");
    report.add("derived", "half_saturation_B", kMu0 * ms_ / chi0_, "T", "mu0 Ms / chi0");
  }

  void execute(const std::filesystem::path& staging_dir, io::Hdf5File& results,
               app::Progress& progress) const override {
    progress.set_total(1);
    const MagnetizationCurve curve =
        froehlich_kennelly_loop(chi0_, ms_, sweep_.max_t, sweep_.grid_step_t());
    progress.advance();
    const app::ResultCheck check = write_curve(staging_dir, results, curve, {ms_, chi0_});
    check.throw_if_any("written as NaN in summary.csv and /curve");
  }

 private:
  double chi0_ = 70.0;  // Fig. 1.6
  double ms_ = 1.6e6;   // A/m, Fig. 1.6
  FieldSweep sweep_;
};

const app::RunTypeRegistrar froehlich_kennelly_run_registrar(
    {"froehlich_kennelly",
     "Froehlich-Kennelly magnetization curve of one particle, "
     "eq. 1.5 (Fig. 1.6)",
     [](const config::TableReader& root) {
       return std::make_unique<FroehlichKennellyPlan>(root);
     }});

}  // namespace
}  // namespace mresim::magnetism::runs
