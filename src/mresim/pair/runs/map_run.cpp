// Run type "pair_map": critical fields H_C1, H_C2 and dH over a grid of (k, S0) for the
// single-spring model (Fig. 2.5) or (theta_H, S0) (Fig. 2.9, three-spring with Puljiz springs),
// with the eq. 2.10 threshold alongside for k maps.
#include <fmt/format.h>

#include <cmath>
#include <memory>

#include "mresim/app/run_type.hpp"
#include "mresim/pair/parameter_map.hpp"
#include "mresim/pair/runs/grid_axis.hpp"
#include "mresim/pair/runs/pair_outputs.hpp"
#include "mresim/pair/stiffness.hpp"

namespace mresim::pair::runs {
namespace {

using config::Range;

class MapPlan final : public app::RunPlan {
 public:
  explicit MapPlan(const config::TableReader& root) {
    const config::TableReader map = root.table("map");
    row_parameter_ = map.choice("rows", {"k", "angle"});
    base_ = read_pair_setup(root, PairSetup{}, true, row_parameter_ != "k");
    if (row_parameter_ == "k") {
      if (base_.model != SpringModel::single) {
        map.fail("rows", "\"k\"", "k rows need springs.model = \"single\" (Fig. 2.5)");
      }
      rows_ = read_grid_axis(map, "row", Range::positive(), "N/m", "log");
    } else {
      rows_ = read_grid_axis(map, "row", Range::between(0.0, 90.0), "deg", "linear");
    }
    separations_ = read_grid_axis(map, "separation", Range::positive(), "m", "linear");
    require_separations(map, "separation", separations_, base_.material);
    if (row_parameter_ == "k") check_k_rows(map);
    PairSetup first = base_;  // the zero-field state depends on k, not on the angle
    if (row_parameter_ == "k") first.stiffness = {StiffnessSource::Kind::spring_constant, rows_[0]};
    const std::string w = wca_cutoff_warning(
        map.has("separation_values") ? "map.separation_values" : "map.separation_min", separations_,
        first);
    if (!w.empty()) warnings_.push_back(w);
    print_warnings(warnings_);
  }

  void describe(app::InfoReport& report) const override {
    describe_pair(report, "base pair", base_);
    report.add_text("map", "rows", row_parameter_ == "k" ? "k (N/m)" : "field angle theta_H (deg)");
    report.add_integer("map", "row_count", static_cast<std::int64_t>(rows_.size()));
    report.add("map", "row_first", rows_.front(), row_parameter_ == "k" ? "N/m" : "deg");
    report.add("map", "row_last", rows_.back(), row_parameter_ == "k" ? "N/m" : "deg");
    report.add_integer("map", "separation_count", static_cast<std::int64_t>(separations_.size()));
    report.add("map", "separation_first", separations_.front(), "m");
    report.add("map", "separation_last", separations_.back(), "m");
    report.add_integer("map", "points",
                       static_cast<std::int64_t>(rows_.size() * separations_.size()));
    SweepOptions quadrant = base_.sweep;
    quadrant.first_quadrant_only = true;
    report.add_integer("map", "steps_per_point",
                       static_cast<std::int64_t>(sweep_points(quadrant).size()), "",
                       "first quadrant 0 -> +max -> 0; the loop is odd in B");
    if (row_parameter_ == "k") {
      for (const double k : rows_) {
        report.add("eq. 2.10 threshold", fmt::format("S0_max(k = {:.4g} N/m)", k),
                   clustering_threshold_separation(base_.material, k), "m");
      }
    }
  }

  void execute(const std::filesystem::path& staging_dir, io::Hdf5File& results,
               app::Progress& progress) const override {
    progress.set_total(rows_.size() * separations_.size());
    CriticalFieldOptions options;
    options.tolerance = base_.critical_field_tolerance;
    const CriticalFieldGrid grid = map_critical_fields(
        rows_.size(), separations_.size(),
        [this](std::size_t r, std::size_t c) { return point(r, c); }, options,
        [&progress] { progress.advance(); });
    write(staging_dir, results, grid);
  }

 private:
  MapPointSetup point(std::size_t row, std::size_t col) const {
    PairSetup s = base_;
    if (row_parameter_ == "k") {
      s.stiffness.kind = StiffnessSource::Kind::spring_constant;
      s.stiffness.k = rows_[row];
    } else {
      s.sweep.theta_h_deg = rows_[row];
    }
    return {s.system_at(separations_[col]), s.sweep};
  }

  void write(const std::filesystem::path& dir, io::Hdf5File& h5,
             const CriticalFieldGrid& grid) const {
    const std::size_t rows = rows_.size();
    const std::size_t cols = separations_.size();
    io::CsvWriter csv(dir / "summary.csv",
                      {"row", "col", "row_value", "S0_m", "hysteresis", "HC1_T", "HC2_T", "dH_T",
                       "dH_uncertainty_T", "dH_resolved", "k12_N_per_m", "k0_N_per_m", "valid"});
    std::vector<double> hc1;
    std::vector<double> hc2;
    std::vector<double> dh;
    std::vector<double> dh_uncertainty;  // T, the error bound of each dH
    std::vector<double> dh_resolved;     // 1 where dH is known to 10 % (kResolvedFraction)
    std::vector<std::int64_t> hysteresis;
    std::vector<double> valid;
    app::ResultCheck check("non-finite results");
    app::ResultCheck unmarked("critical fields not valid");
    for (std::size_t r = 0; r < rows; ++r) {
      for (std::size_t c = 0; c < cols; ++c) {
        const CriticalFields& f = grid.at(r, c);
        const PairSystem p = point(r, c).system;
        const bool ok = std::isfinite(f.hc1) && std::isfinite(f.hc2) && f.valid();
        const std::string where =
            fmt::format("row {}, col {} (S0 = {:.6g} m)", r, c, separations_[c]);
        check_critical_fields(check, where, f);
        check_critical_fields_valid(unmarked, where, f);
        csv.row({static_cast<double>(r), static_cast<double>(c), rows_[r], separations_[c],
                 f.hysteresis ? 1.0 : 0.0, f.hc1, f.hc2, f.delta(), f.delta_uncertainty,
                 f.delta_resolved ? 1.0 : 0.0, p.springs.k12, p.springs.k0, ok ? 1.0 : 0.0});
        hc1.push_back(f.hc1);
        hc2.push_back(f.hc2);
        dh.push_back(f.delta());
        dh_uncertainty.push_back(f.delta_uncertainty);
        dh_resolved.push_back(f.delta_resolved ? 1.0 : 0.0);
        hysteresis.push_back(f.hysteresis ? 1 : 0);
        valid.push_back(ok ? 1.0 : 0.0);
      }
    }
    h5.write_array("/map/valid", {rows, cols}, valid, "1");
    write_warnings_attribute(h5, warnings_);
    h5.write_string_attribute("/map", "row_parameter", row_parameter_);
    h5.write_number_attribute("/map", "critical_field_uncertainty_T",
                              0.5 * base_.critical_field_tolerance);
    h5.write_vector("/map/row_values", rows_, row_parameter_ == "k" ? "N/m" : "deg");
    h5.write_vector("/map/separations", separations_, "m");
    h5.write_matrix("/map/HC1", rows, cols, hc1, "T");
    h5.write_matrix("/map/HC2", rows, cols, hc2, "T");
    h5.write_matrix("/map/dH", rows, cols, dh, "T");
    h5.write_matrix("/map/dH_uncertainty", rows, cols, dh_uncertainty, "T");
    h5.write_array("/map/dH_resolved", {rows, cols}, dh_resolved, "1");
    std::vector<double> as_double(hysteresis.begin(), hysteresis.end());
    h5.write_array("/map/hysteresis", {rows, cols}, as_double, "1");
    if (row_parameter_ == "k") {
      io::CsvWriter threshold(dir / "threshold.csv", {"k_N_per_m", "S0_threshold_m"});
      std::vector<double> s0_max;
      for (double k : rows_) {
        s0_max.push_back(clustering_threshold_separation(base_.material, k));
        threshold.row({k, s0_max.back()});
      }
      h5.write_vector("/map/eq_2_10_threshold", s0_max, "m");
    }
    check.throw_if_any(
        "written as NaN; see /map/valid in results.h5 and the valid column of "
        "summary.csv");
    unmarked.throw_if_any("see /map/valid in results.h5 and the valid column of summary.csv");
  }

  // The spring constants of the rows in the solver's units (k R^2 / mu0 Ms^2 V) and the spring
  // energy scale k S0^2 must be finite.
  void check_k_rows(const config::TableReader& map) const {
    const double r = base_.material.radius;
    const double scale = base_.material.magnetic_energy_scale();
    const double s0 = separations_.back();
    for (const double k : rows_) {
      if (!std::isfinite(k * r * r / scale) || !std::isfinite(k * s0 * s0)) {
        map.fail(map.has("row_values") ? "row_values" : "row_max", k,
                 fmt::format("gives the spring energy scale k S0^2 = {:.3g} J, which overflows "
                             "next to the magnetic energy scale mu0 Ms^2 V = {:.3g} J",
                             k * s0 * s0, scale));
      }
    }
  }

  std::string row_parameter_;
  PairSetup base_;
  std::vector<double> rows_;
  std::vector<double> separations_;
  std::vector<std::string> warnings_;  // read-time warnings, also in results.h5 /@warnings
};

const app::RunTypeRegistrar map_run_registrar({"pair_map",
                                               "Critical-field maps over (k, S0) or (theta_H, S0) "
                                               "(Figs. 2.5, 2.9)",
                                               [](const config::TableReader& root) {
                                                 return std::make_unique<MapPlan>(root);
                                               }});

}  // namespace
}  // namespace mresim::pair::runs
