// Run type "pair_ensemble": loops averaged over a Gaussian-weighted distribution of zero-field
// separations S0 (Section 3.6, Fig. 3.5), one ensemble per [[case]] (e.g. per k), with the loop
// widening Delta(M/Ms)(H) and the differential susceptibility.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <memory>

#include "mresim/app/run_type.hpp"
#include "mresim/pair/ensemble.hpp"
#include "mresim/pair/runs/grid_axis.hpp"
#include "mresim/pair/runs/pair_outputs.hpp"

namespace mresim::pair::runs {
namespace {

using config::Range;

class EnsemblePlan final : public app::RunPlan {
 public:
  explicit EnsemblePlan(const config::TableReader& root) : cases_(read_pair_cases(root)) {
    const config::TableReader e = root.table("ensemble");
    separations_ = read_grid_axis(e, "separation", Range::positive(), "m", "linear");
    mean_ = e.number("mean", Range::positive(), "m");
    sd_ = e.number("standard_deviation", Range::positive(), "m");
    smoothing_ = e.choice_or("smoothing", "five_point", {"five_point", "none"}) == "five_point";
    for (const PairSetup& c : cases_)
      require_separations(e, "separation", separations_, c.material);
    check_weights(e);
    weights_ = gaussian_weights(separations_, mean_, sd_);
    const std::string key =
        e.has("separation_values") ? "ensemble.separation_values" : "ensemble.separation_min";
    for (std::size_t c = 0; c < cases_.size(); ++c) {
      const std::string w = wca_cutoff_warning(
          cases_.size() == 1 ? key : fmt::format("case[{}] ({}): {}", c, cases_[c].label, key),
          separations_, cases_[c]);
      if (!w.empty()) warnings_.push_back(w);
    }
    print_warnings(warnings_);
  }

  void describe(app::InfoReport& report) const override {
    report.add_integer("ensemble", "members", static_cast<std::int64_t>(separations_.size()));
    report.add("ensemble", "separation_first", separations_.front(), "m");
    report.add("ensemble", "separation_last", separations_.back(), "m");
    report.add("ensemble", "mean", mean_, "m", "Gaussian weight centre");
    report.add("ensemble", "standard_deviation", sd_, "m");
    double mean_s0 = 0.0;
    for (std::size_t i = 0; i < separations_.size(); ++i) mean_s0 += weights_[i] * separations_[i];
    report.add("ensemble", "weighted_mean_separation", mean_s0, "m",
               "the Gaussian is truncated to the separation range");
    report.add_text("ensemble", "smoothing", smoothing_ ? "five-point average" : "none");
    for (std::size_t i = 0; i < cases_.size(); ++i) {
      describe_pair(report, fmt::format("case {}: {}", i, cases_[i].label), cases_[i]);
    }
  }

  void execute(const std::filesystem::path& staging_dir, io::Hdf5File& h5,
               app::Progress& progress) const override {
    progress.set_total(cases_.size());
    app::ResultCheck check("non-finite results");
    io::CsvWriter summary(staging_dir / "summary.csv", {"case", "label", "step", "branch", "B_T",
                                                        "M_over_Ms", "dM_dB_per_T", "valid"});
    io::CsvWriter widening_csv(staging_dir / "widening.csv",
                               {"case", "label", "B_T", "dM_over_Ms", "dM_over_Ms_smoothed"});
    for (std::size_t c = 0; c < cases_.size(); ++c) {
      std::vector<PairSystem> members;
      for (double s0 : separations_) members.push_back(cases_[c].system_at(s0));
      const EnsembleResult r = ensemble_average(members, weights_, cases_[c].sweep);
      const std::vector<double> chi = differential_susceptibility(r.average, smoothing_);
      const LoopWidening widening = loop_widening(r.average);
      const std::vector<double> smooth = five_point_average(widening.widening);
      const MagnetizationLoop& loop = r.average;
      std::vector<std::int64_t> valid;
      for (std::size_t i = 0; i < loop.field.size(); ++i) {
        const std::string where = fmt::format("case {} ({}), step {} (B = {:.6g} T)", c,
                                              cases_[c].label, i, loop.field[i]);
        const bool ok = check.finite(loop.magnetization[i], "average M/Ms", where) &&
                        check.finite(chi[i], "dM/dB", where);
        valid.push_back(ok ? 1 : 0);
        summary.row_cells({static_cast<double>(c), cases_[c].label, static_cast<double>(i),
                           static_cast<double>(loop.branch[i]), loop.field[i],
                           loop.magnetization[i], chi[i], ok ? 1.0 : 0.0});
      }
      h5.write_int_vector(fmt::format("/cases/{}/valid", c), valid);
      for (std::size_t i = 0; i < widening.field.size(); ++i) {
        widening_csv.row_cells({static_cast<double>(c), cases_[c].label, widening.field[i],
                                widening.widening[i], smooth[i]});
      }
      write_hdf5(h5, c, r, chi, widening, smooth);
      progress.advance();
    }
    write_warnings_attribute(h5, warnings_);
    check.throw_if_any(
        "written as NaN; see /cases/<i>/valid in results.h5 and the valid column of summary.csv");
  }

 private:
  void write_hdf5(io::Hdf5File& h5, std::size_t c, const EnsembleResult& r,
                  const std::vector<double>& chi, const LoopWidening& widening,
                  const std::vector<double>& smooth) const {
    const std::string g = fmt::format("/cases/{}", c);
    h5.write_string_attribute(g, "label", cases_[c].label);
    h5.write_vector(g + "/field", r.average.field, "T");
    std::vector<std::int64_t> branch(r.average.branch.begin(), r.average.branch.end());
    h5.write_int_vector(g + "/branch", branch);
    h5.write_vector(g + "/magnetization_along_field", r.average.magnetization, "1");
    h5.write_vector(g + "/susceptibility", chi, "1/T");
    h5.write_vector(g + "/widening/field", widening.field, "T");
    h5.write_vector(g + "/widening/value", widening.widening, "1");
    h5.write_vector(g + "/widening/smoothed", smooth, "1");
    std::vector<double> members;
    for (const MagnetizationLoop& m : r.members) {
      members.insert(members.end(), m.magnetization.begin(), m.magnetization.end());
    }
    h5.write_matrix(g + "/members/magnetization_along_field", r.members.size(),
                    r.average.field.size(), members, "1");
    h5.write_vector(g + "/members/separations", separations_, "m");
    h5.write_vector(g + "/members/weights", weights_, "1");
  }

  // The Gaussian exp(-(S0 - mean)^2 / (2 sd^2)) must not vanish (underflow to 0) at every
  // member, or the normalised weights are 0/0: typically mean or sd given in um, not m.
  void check_weights(const config::TableReader& e) const {
    for (const double s0 : separations_) {
      const double z = (s0 - mean_) / sd_;
      if (std::exp(-0.5 * z * z) > 0.0) return;
    }
    const double lo = separations_.front();
    const double hi = separations_.back();
    const bool mean_outside = mean_ < std::min(lo, hi) || mean_ > std::max(lo, hi);
    const std::string what = fmt::format(
        "the Gaussian weights exp(-(S0 - mean)^2 / (2 sd^2)) with mean = {} m, "
        "standard_deviation = {} m vanish at every separation from {:.6g} to {:.6g} m; mean and "
        "standard_deviation are in metres (4.8 um is 4.8e-6), like the separations",
        mean_, sd_, lo, hi);
    e.fail(mean_outside ? "mean" : "standard_deviation", mean_outside ? mean_ : sd_, what);
  }

  std::vector<PairSetup> cases_;
  std::vector<double> separations_;
  double mean_ = 0.0;
  double sd_ = 0.0;
  bool smoothing_ = true;
  std::vector<double> weights_;
  std::vector<std::string> warnings_;  // read-time warnings, also in results.h5 /@warnings
};

const app::RunTypeRegistrar ensemble_run_registrar(
    {"pair_ensemble",
     "Loops averaged over a weighted distribution of S0, loop "
     "widening and susceptibility (Fig. 3.5)",
     [](const config::TableReader& root) { return std::make_unique<EnsemblePlan>(root); }});

}  // namespace
}  // namespace mresim::pair::runs
