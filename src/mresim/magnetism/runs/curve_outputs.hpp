#pragma once

// Shared parts of the single-particle magnetization-curve run types of Chapter 1
// (`froehlich_kennelly`, Fig. 1.6; `preisach`, Fig. 1.5): the [field] table, its `info` lines,
// and the outputs. Keys and columns are documented in docs/run-files.md (Chapter 1 section).

#include <filesystem>

#include "mresim/app/info_report.hpp"
#include "mresim/app/invalid_results.hpp"
#include "mresim/config/table_reader.hpp"
#include "mresim/io/hdf5_file.hpp"
#include "mresim/magnetism/magnetization_curve.hpp"

namespace mresim::magnetism::runs {

// The major-loop sweep 0 -> +max -> -max -> +max of [field].
struct FieldSweep {
  double max_t = 1.0;    // field.max, T (applied B = mu0 H)
  double step_t = 0.01;  // field.step, T
  long steps = 100;      // max / step, a whole number (checked)

  // Points of the sweep: 5 steps + 1 (see major_loop_sweep).
  [[nodiscard]] long samples() const { return 5 * steps + 1; }
  // The step handed to major_loop_sweep: max / steps exactly, so its ceil() finds `steps` even
  // where max / step is a few ulps above the whole number this reader accepted.
  [[nodiscard]] double grid_step_t() const { return max_t / static_cast<double>(steps); }
};

// Reads the optional [field] table (max in (0, 1e100] T, default `default_max_t`; step > 0, default
// 0.01 T; max a whole number of steps, at most 1e6 of them). Throws config::ConfigError.
FieldSweep read_field_sweep(const config::TableReader& root, double default_max_t);

// The [field] lines of `mresim info`: max, step, steps per branch, samples.
void describe_field(app::InfoReport& report, const FieldSweep& sweep);

// What the loop is known to be, for the attributes of /curve.
struct CurveAttributes {
  double saturation_magnetization_a_per_m;  // NaN where the model is normalized (Preisach)
  double initial_susceptibility;            // NaN: attribute not written
};

// Writes summary.csv (step, branch, B_T, M_over_Ms) into `staging_dir` and /curve/field,
// /curve/branch, /curve/magnetization into `results`, with the /curve attributes
// coercive_field_T and remanence (from loop_features) plus `attributes`. If the descending
// branch never crosses B = 0 or M = 0 (a minor loop that never switches), the coercive field
// and remanence are written as NaN and a warning goes to stderr. Non-finite points (overflow)
// are written as NaN and collected in the returned check, which the run type throws at the end
// of execute() (app::InvalidResults, exit status 4).
// Reading also bounds field.max to <= 1e100 T.
[[nodiscard]] app::ResultCheck write_curve(const std::filesystem::path& staging_dir,
                                           io::Hdf5File& results, const MagnetizationCurve& curve,
                                           const CurveAttributes& attributes);

}  // namespace mresim::magnetism::runs
