#include "mresim/magnetism/runs/curve_outputs.hpp"

#include <fmt/format.h>

#include <cmath>
#include <cstdint>
#include <iostream>
#include <limits>
#include <stdexcept>
#include <vector>

#include "mresim/io/csv_writer.hpp"
#include "mresim/magnetism/loop_features.hpp"

namespace mresim::magnetism::runs {

using config::Range;

namespace {

// B_c and M_r as Fig. 1.5 marks them, read off the descending branch (loop_features.hpp); NaN
// with a warning when the branch never crosses M = 0 or B = 0.
LoopFeatures features_or_nan(const MagnetizationCurve& curve) {
  try {
    const LoopFeatures f = loop_features(curve);
    return {f.coercive_field_t + 0.0, f.remanence + 0.0};  // + 0.0: -0 (anhysteretic) -> 0
  } catch (const std::invalid_argument& e) {
    std::cerr << fmt::format(
        "mresim: warning: no coercive field or remanence ({}); written as "
        "NaN. Is field.max beyond the switching fields?\n",
        e.what());
  }
  const double nan = std::numeric_limits<double>::quiet_NaN();
  return {nan, nan};
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

void write_curve(const std::filesystem::path& staging_dir, io::Hdf5File& results,
                 const MagnetizationCurve& curve, const CurveAttributes& attributes) {
  const std::size_t n = curve.b_tesla.size();
  io::CsvWriter csv(staging_dir / "summary.csv", {"step", "branch", "B_T", "M_over_Ms"});
  std::vector<std::int64_t> branch(n);
  for (std::size_t i = 0; i < n; ++i) {
    branch[i] = curve.branch[i];
    csv.row({static_cast<double>(i), static_cast<double>(curve.branch[i]), curve.b_tesla[i],
             curve.m_over_ms[i]});
  }
  csv.close();

  results.write_vector("/curve/field", curve.b_tesla, "T");
  results.write_int_vector("/curve/branch", branch);
  results.write_vector("/curve/magnetization", curve.m_over_ms, "1");  // M/Ms

  const LoopFeatures features = features_or_nan(curve);
  results.write_number_attribute("/curve", "coercive_field_T", features.coercive_field_t);
  results.write_number_attribute("/curve", "remanence", features.remanence);
  results.write_number_attribute("/curve", "saturation_magnetization_A_per_m",
                                 attributes.saturation_magnetization_a_per_m);
  if (!std::isnan(attributes.initial_susceptibility)) {
    results.write_number_attribute("/curve", "initial_susceptibility",
                                   attributes.initial_susceptibility);
  }
}

}  // namespace mresim::magnetism::runs
