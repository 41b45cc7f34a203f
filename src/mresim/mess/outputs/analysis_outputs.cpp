#include "mresim/mess/outputs/analysis_outputs.hpp"

#include <fmt/format.h>

#include <limits>
#include <string>

#include "mresim/io/csv_writer.hpp"
#include "mresim/mess/analysis/modulus_fit.hpp"
#include "mresim/mess/analysis/second_fit.hpp"
#include "mresim/mess/protocols/protocol.hpp"

namespace mresim::mess_protocol {

namespace fs = std::filesystem;
namespace mc = mresim::mess_config;
namespace ma = mresim::mess_analysis;

namespace {

constexpr double kNoFit = std::numeric_limits<double>::quiet_NaN();

// The modulus of every field (Section 4.2.8) with what the outputs say about its fit.
struct FieldFits {
  std::vector<double> magnitude;  // T
  std::vector<double> modulus;    // Pa (J/m^3 torsion); NaN where underdetermined
  std::vector<double> offset;     // J/m^3
  std::vector<double> rms;        // J/m^3 or Pa
  std::vector<double> mr;         // %
  std::vector<std::int64_t> first;
  std::vector<std::int64_t> points;
  std::vector<std::int64_t> split;
  std::vector<std::int64_t> valid;
  std::vector<std::int64_t> mr_valid;  // both this field's and the first field's fit are valid
  std::vector<std::string> problem;    // "" where valid
  std::vector<ma::SecondFit> second;   // after the kink; "no kink" for stress runs
};

ma::SecondFit no_second_fit(std::string problem) {
  ma::SecondFit s;
  s.modulus = s.slope = s.offset = s.rms_residual = kNoFit;
  s.problem = std::move(problem);
  return s;
}

// The fit is the one the protocol names (protocols/protocol.hpp, Analysis).
FieldFits fit_fields(const mc::MessSpec& spec, const Analysis& analysis,
                     const std::vector<StepRecord>& records,
                     const std::vector<double>& energy_density) {
  FieldFits out;
  const std::size_t fields = spec.field.values.size();
  for (std::size_t f = 0; f < fields; ++f) {
    std::vector<double> strain;
    std::vector<double> density;
    std::vector<double> stress;
    std::vector<bool> converged;
    for (std::size_t i = 0; i < records.size(); ++i) {
      if (records[i].step.field_index != f) continue;
      strain.push_back(records[i].measured_strain);
      density.push_back(energy_density[i]);
      stress.push_back(records[i].step.load_value);
      converged.push_back(records[i].converged);
    }
    out.magnitude.push_back(spec.field.values[f].norm());
    if (analysis.kind == AnalysisKind::energy_modulus) {
      ma::FitOptions options;
      options.drop_zero_point_above_next = analysis.drop_zero_point_above_next;
      options.converged = converged;
      const ma::QuadraticFit fit = ma::fit_energy_density(strain, density, options);
      out.modulus.push_back(fit.modulus);
      out.offset.push_back(fit.offset);
      out.rms.push_back(fit.rms_residual);
      out.first.push_back(static_cast<std::int64_t>(fit.first));
      out.points.push_back(static_cast<std::int64_t>(fit.points));
      out.split.push_back(fit.split ? 1 : 0);
      out.valid.push_back(fit.valid ? 1 : 0);
      out.problem.push_back(fit.problem);
      out.second.push_back(ma::fit_after_kink(strain, density, fit, options));
    } else {
      const ma::LinearFit fit = ma::fit_stress_strain(strain, stress, converged);
      out.modulus.push_back(fit.modulus);
      out.offset.push_back(0.0);
      out.rms.push_back(fit.rms_residual);
      out.first.push_back(0);
      out.points.push_back(static_cast<std::int64_t>(fit.points));
      out.split.push_back(0);
      out.valid.push_back(fit.valid ? 1 : 0);
      out.problem.push_back(fit.problem);
      out.second.push_back(no_second_fit("stress runs fit one line (no kink rule)"));
    }
  }
  for (std::size_t f = 0; f < fields; ++f) {
    out.mr.push_back(ma::mr_effect_percent(out.modulus[f], out.modulus.front()));
    out.mr_valid.push_back(out.valid[f] != 0 && out.valid.front() != 0 ? 1 : 0);
  }
  return out;
}

template <typename Get>
auto second_column(const FieldFits& fits, Get get) {
  std::vector<decltype(get(fits.second.front()))> out;
  for (const ma::SecondFit& s : fits.second) out.push_back(get(s));
  return out;
}

void write_second_fits(io::Hdf5File& results, const FieldFits& fits, const char* unit) {
  results.write_string_attribute("/analysis", "second_form", ma::kSecondFitForm);
  results.write_vector("/analysis/second_modulus",
                       second_column(fits, [](const ma::SecondFit& s) { return s.modulus; }), unit);
  results.write_vector("/analysis/second_slope",
                       second_column(fits, [](const ma::SecondFit& s) { return s.slope; }),
                       "J/m^3");
  results.write_vector("/analysis/second_offset",
                       second_column(fits, [](const ma::SecondFit& s) { return s.offset; }),
                       "J/m^3");
  results.write_vector("/analysis/second_rms_residual",
                       second_column(fits, [](const ma::SecondFit& s) { return s.rms_residual; }),
                       "J/m^3");
  results.write_int_vector("/analysis/second_first_point",
                           second_column(fits, [](const ma::SecondFit& s) {
                             return static_cast<std::int64_t>(s.first);
                           }));
  results.write_int_vector("/analysis/second_fit_points",
                           second_column(fits, [](const ma::SecondFit& s) {
                             return static_cast<std::int64_t>(s.points);
                           }));
  results.write_int_vector("/analysis/second_valid",
                           second_column(fits, [](const ma::SecondFit& s) {
                             return static_cast<std::int64_t>(s.valid ? 1 : 0);
                           }));
  results.write_string_vector(
      "/analysis/second_problem",
      second_column(fits, [](const ma::SecondFit& s) { return s.problem; }));
}

}  // namespace

void write_analysis(const fs::path& run_dir, io::Hdf5File& results, const ProtocolRunner& runner,
                    const std::vector<StepRecord>& records,
                    const std::vector<double>& energy_density, MessResultCheck& check) {
  const mc::MessSpec& spec = runner.spec();
  const Analysis analysis = spec.protocol->analysis();
  const bool energy = analysis.kind == AnalysisKind::energy_modulus;
  const FieldFits fits = fit_fields(spec, analysis, records, energy_density);
  const std::string& name = analysis.modulus_name;
  for (std::size_t f = 0; f < fits.valid.size(); ++f) {
    if (fits.valid[f] != 0) continue;
    check.invalid_fits.push_back(fmt::format("{} at |B| = {:.4g} T (field {}): {}", name,
                                             fits.magnitude[f], f, fits.problem[f]));
  }

  const char* unit = name == "torsion_stiffness" ? "J/m^3" : "Pa";
  results.write_string_attribute("/analysis", "modulus_name", name);
  results.write_string_attribute("/analysis", "method",
                                 energy ? "energy density = a x^2/2 + c, least squares"
                                        : "stress = a x, least squares through 0");
  results.write_vector("/analysis/field_magnitude", fits.magnitude, "T");
  results.write_vector("/analysis/modulus", fits.modulus, unit);
  results.write_vector("/analysis/offset", fits.offset, "J/m^3");
  results.write_vector("/analysis/rms_residual", fits.rms, energy ? "J/m^3" : "Pa");
  results.write_int_vector("/analysis/first_point", fits.first);
  results.write_int_vector("/analysis/fit_points", fits.points);
  results.write_int_vector("/analysis/split", fits.split);
  results.write_int_vector("/analysis/valid", fits.valid);
  results.write_string_vector("/analysis/problem", fits.problem);
  results.write_vector("/analysis/mr_effect", fits.mr, "%");
  results.write_int_vector("/analysis/mr_effect_valid", fits.mr_valid);
  write_second_fits(results, fits, unit);

  io::CsvWriter csv(
      run_dir / "modulus.csv",
      {"field_index", "B_T", name + (name == "torsion_stiffness" ? "_J_m3" : "_Pa"), "offset_J_m3",
       "residual", "first_point", "points", "valid", "mr_effect_percent", "mr_effect_valid",
       "second_modulus", "second_slope", "second_offset", "second_residual", "second_first_point",
       "second_points", "second_valid"});
  for (std::size_t f = 0; f < fits.magnitude.size(); ++f) {
    const ma::SecondFit& s = fits.second[f];
    csv.row({static_cast<double>(f), fits.magnitude[f], fits.modulus[f], fits.offset[f],
             fits.rms[f], static_cast<double>(fits.first[f]), static_cast<double>(fits.points[f]),
             static_cast<double>(fits.valid[f]), fits.mr[f], static_cast<double>(fits.mr_valid[f]),
             s.modulus, s.slope, s.offset, s.rms_residual, static_cast<double>(s.first),
             static_cast<double>(s.points), s.valid ? 1.0 : 0.0});
  }
}

}  // namespace mresim::mess_protocol
