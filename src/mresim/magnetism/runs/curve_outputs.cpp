#include "mresim/magnetism/runs/curve_outputs.hpp"

#include <fmt/format.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "mresim/app/run_output.hpp"
#include "mresim/io/csv_writer.hpp"
#include "mresim/magnetism/loop_features.hpp"

namespace mresim::magnetism::runs {

using config::Range;

constexpr double kMaxFieldT = 1e100;

namespace {

LoopFeatures nan_features() {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  return {nan, nan};
}

// B_c and M_r as Fig. 1.5 marks them, read off the descending branch (loop_features.hpp); NaN
// with a warning when the branch never crosses M = 0 or B = 0.
LoopFeatures features_or_nan(const MagnetizationCurve& curve, bool curve_finite) {
  try {
    const LoopFeatures f = loop_features(curve);
    return {f.coercive_field_t + 0.0, f.remanence + 0.0};  // + 0.0: -0 (anhysteretic) -> 0
  } catch (const std::invalid_argument& e) {
    // A loop that never switches legitimately has no B_c or M_r; a loop with non-finite
    // points is flagged by write_curve instead (no warning: it is an error there).
    if (!curve_finite) return nan_features();
    app::warn(
        fmt::format("no coercive field or remanence ({}); written as NaN. Is field.max beyond the "
                    "switching fields?",
                    e.what()));
  }
  return nan_features();
}

}  // namespace

FieldSweep read_field_sweep(const config::TableReader& root, double default_max_t) {
  FieldSweep sweep;
  sweep.max_t = default_max_t;
  const auto t = root.optional_table("field");
  if (!t) {
    sweep.steps = std::lround(sweep.max_t / sweep.step_t);
    return sweep;
  }
  sweep.max_t = t->number_or("max", sweep.max_t, Range::positive(), "T");
  sweep.step_t = t->number_or("step", sweep.step_t, Range::positive(), "T");
  // A bound on the field itself, before any derived scale: H = B / mu0 and products such as
  // chi0 H Ms (eq. 1.5) must stay far from the largest double.
  if (sweep.max_t > kMaxFieldT) {
    t->fail("max", sweep.max_t,
            fmt::format("must be <= {:.0e} T (H = B / mu0 and the products of eq. 1.5 must stay "
                        "finite)",
                        kMaxFieldT));
  }
  // Same rule and wording as the two-dipole [field] (pair_setup.cpp): the grid must hit
  // 0 and +-max exactly, so the turning points and B = 0 (remanence) are sampled.
  const double steps = sweep.max_t / sweep.step_t;
  if (std::abs(steps - std::round(steps)) > 1e-6 * steps) {
    t->fail("max", sweep.max_t,
            fmt::format("must be a whole number of field.step = {} T (the sweep visits "
                        "0, +max, -max exactly)",
                        sweep.step_t));
  }
  if (std::round(steps) > 1e6) {
    t->fail("step", sweep.step_t, "must give at most 1e6 steps up to field.max");
  }
  // A max far below step rounds to 0 steps and is caught above (|0 - steps| = steps).
  sweep.steps = std::lround(steps);
  return sweep;
}

void describe_field(app::InfoReport& report, const FieldSweep& sweep) {
  report.add("field", "max", sweep.max_t, "T", "applied B = mu0 H");
  report.add("field", "step", sweep.step_t, "T");
  report.add_integer("field", "steps_per_branch", sweep.steps, "", "max / step");
  report.add_integer("field", "samples", sweep.samples(), "",
                     "0 -> +max -> -max -> +max, 5 steps + 1");
}

app::ResultCheck write_curve(const std::filesystem::path& staging_dir, io::Hdf5File& results,
                             const MagnetizationCurve& curve, const CurveAttributes& attributes) {
  const std::size_t n = curve.b_tesla.size();
  app::ResultCheck check("non-finite results");
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::vector<double> field(curve.b_tesla);
  std::vector<double> magnetization(curve.m_over_ms);
  for (std::size_t i = 0; i < n; ++i) {
    const std::string where = fmt::format("step {}", i);
    if (!check.finite(field[i], "B_T", where)) field[i] = nan;
    if (!check.finite(magnetization[i], "M_over_Ms",
                      fmt::format("{} (B = {} T)", where, curve.b_tesla[i]))) {
      magnetization[i] = nan;
    }
  }
  io::CsvWriter csv(staging_dir / "summary.csv", {"step", "branch", "B_T", "M_over_Ms"});
  std::vector<std::int64_t> branch(n);
  for (std::size_t i = 0; i < n; ++i) {
    branch[i] = curve.branch[i];
    csv.row(
        {static_cast<double>(i), static_cast<double>(curve.branch[i]), field[i], magnetization[i]});
  }
  csv.close();

  results.write_vector("/curve/field", field, "T");
  results.write_int_vector("/curve/branch", branch);
  results.write_vector("/curve/magnetization", magnetization, "1");  // M/Ms

  const bool curve_finite = !check.any();
  const LoopFeatures features = features_or_nan(curve, curve_finite);
  if (curve_finite) {
    // Features of a finite curve are finite when they exist; NaN here is the no-crossing case.
    if (std::isinf(features.coercive_field_t)) check.flag("coercive_field_T", "/curve");
    if (std::isinf(features.remanence)) check.flag("remanence", "/curve");
  } else {
    check.flag("coercive_field_T and remanence", "/curve (from a non-finite curve)");
  }
  results.write_number_attribute("/curve", "coercive_field_T", features.coercive_field_t);
  results.write_number_attribute("/curve", "remanence", features.remanence);
  results.write_number_attribute("/curve", "saturation_magnetization_A_per_m",
                                 attributes.saturation_magnetization_a_per_m);
  if (!std::isnan(attributes.initial_susceptibility)) {
    results.write_number_attribute("/curve", "initial_susceptibility",
                                   attributes.initial_susceptibility);
  }
  return check;
}

}  // namespace mresim::magnetism::runs
