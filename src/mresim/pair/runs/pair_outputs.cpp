#include "mresim/pair/runs/pair_outputs.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "mresim/app/run_output.hpp"
#include "mresim/pair/overlap_penalty.hpp"
#include "mresim/pair/stiffness.hpp"

namespace mresim::pair::runs {

std::vector<std::string> loop_csv_columns() {
  return {"case",         "step",        "branch",     "B_T",       "S_m",
          "S_minus_S0_m", "theta_deg",   "m1_x",       "m1_y",      "m1_z",
          "m2_x",         "m2_y",        "m2_z",       "M_over_Ms", "saturated",
          "E_total_J",    "E_zeeman_J",  "E_dipole_J", "E_self_J",  "E_spring_J",
          "E_anchor_J",   "E_penalty_J", "iterations", "converged", "valid"};
}

void append_loop_rows(io::CsvWriter& csv, std::size_t case_index, const PairSetup& setup,
                      const HysteresisLoop& loop) {
  const Eigen::Vector3d direction = field_direction(loop.options.theta_h_deg);
  for (std::size_t i = 0; i < loop.states.size(); ++i) {
    const PairState& s = loop.states[i];
    const Eigen::Vector3d& m = s.magnetization.m;
    const EnergyBreakdown& e = s.energy;
    csv.row({static_cast<double>(case_index),
             static_cast<double>(i),
             static_cast<double>(s.branch),
             s.field,
             s.distance(),
             s.distance() - setup.rest_separation,
             s.rotation_deg(),
             m.x(),
             m.y(),
             m.z(),
             m.x(),
             m.y(),
             m.z(),
             s.magnetization_along(direction),
             s.magnetization.saturated ? 1.0 : 0.0,
             e.total(),
             e.zeeman,
             e.dipole,
             e.self,
             e.spring,
             e.anchor,
             e.penalty,
             static_cast<double>(s.iterations),
             s.converged ? 1.0 : 0.0,
             state_is_finite(s) ? 1.0 : 0.0});
  }
}

void write_loop_hdf5(io::Hdf5File& h5, const std::string& group, const PairSetup& setup,
                     const PairSystem& system, const HysteresisLoop& loop) {
  const std::size_t n = loop.states.size();
  const Eigen::Vector3d direction = field_direction(loop.options.theta_h_deg);
  std::vector<double> field;
  std::vector<double> distance;
  std::vector<double> rotation;
  std::vector<double> along;
  std::vector<double> total;
  std::vector<double> separation;
  std::vector<double> moment;
  std::vector<std::int64_t> branch;
  std::vector<std::int64_t> iterations;
  std::vector<std::int64_t> converged;
  std::vector<std::int64_t> saturated;
  std::vector<std::int64_t> valid;
  std::vector<std::vector<double>> terms(6);
  for (const PairState& s : loop.states) {
    field.push_back(s.field);
    branch.push_back(s.branch);
    distance.push_back(s.distance());
    rotation.push_back(s.rotation_deg());
    along.push_back(s.magnetization_along(direction));
    total.push_back(s.energy.total());
    for (int c = 0; c < 3; ++c) {
      separation.push_back(s.separation(c));
      moment.push_back(s.magnetization.m(c));
    }
    const EnergyBreakdown& e = s.energy;
    const double parts[6] = {e.zeeman, e.dipole, e.self, e.spring, e.anchor, e.penalty};
    for (int t = 0; t < 6; ++t) terms[static_cast<std::size_t>(t)].push_back(parts[t]);
    iterations.push_back(s.iterations);
    converged.push_back(s.converged ? 1 : 0);
    saturated.push_back(s.magnetization.saturated ? 1 : 0);
    valid.push_back(state_is_finite(s) ? 1 : 0);
  }
  h5.write_string_attribute(group, "label", setup.label);
  h5.write_string_attribute(group, "spring_model",
                            system.springs.model == SpringModel::single ? "single" : "three");
  h5.write_number_attribute(group, "rest_separation_m", system.springs.rest_separation);
  h5.write_number_attribute(group, "k12_N_per_m", system.springs.k12);
  h5.write_number_attribute(group, "k0_N_per_m", system.springs.k0);
  h5.write_number_attribute(group, "field_angle_deg", loop.options.theta_h_deg);
  h5.write_string_attribute(group, "penalty",
                            system.penalty.kind == PenaltyKind::tanh ? "tanh" : "wca");
  h5.write_vector(group + "/field", field, "T");
  h5.write_int_vector(group + "/branch", branch);
  h5.write_matrix(group + "/separation", n, 3, separation, "m");
  h5.write_vector(group + "/distance", distance, "m");
  h5.write_vector(group + "/rotation", rotation, "deg");
  h5.write_matrix(group + "/moment", n, 3, moment, "1");  // m1 = m2, units of Ms V
  h5.write_vector(group + "/magnetization_along_field", along, "1");
  h5.write_vector(group + "/energy/total", total, "J");
  const char* names[6] = {"zeeman", "dipole", "self", "spring", "anchor", "penalty"};
  for (std::size_t t = 0; t < 6; ++t) {
    h5.write_vector(group + "/energy/" + names[t], terms[t], "J");
  }
  h5.write_int_vector(group + "/solver/iterations", iterations);
  h5.write_int_vector(group + "/solver/converged", converged);
  h5.write_int_vector(group + "/saturated", saturated);
  h5.write_int_vector(group + "/valid", valid);
}

bool state_is_finite(const PairState& s) {
  const EnergyBreakdown& e = s.energy;
  return s.separation.allFinite() && s.magnetization.m.allFinite() && std::isfinite(s.field) &&
         std::isfinite(e.zeeman) && std::isfinite(e.dipole) && std::isfinite(e.self) &&
         std::isfinite(e.spring) && std::isfinite(e.anchor) && std::isfinite(e.penalty);
}

void check_loop(app::ResultCheck& check, std::size_t case_index, const PairSetup& setup,
                const HysteresisLoop& loop) {
  for (std::size_t i = 0; i < loop.states.size(); ++i) {
    const PairState& s = loop.states[i];
    if (state_is_finite(s)) continue;
    const std::string where =
        fmt::format("case {} ({}), step {} (B = {:.6g} T)", case_index, setup.label, i, s.field);
    if (!s.separation.allFinite()) {
      check.flag("separation", where);
    } else if (!s.magnetization.m.allFinite()) {
      check.flag("moment", where);
    } else {
      check.flag("energy", where);
    }
  }
}

void check_critical_fields(app::ResultCheck& check, const std::string& where,
                           const CriticalFields& f) {
  check.finite(f.hc1, "HC1", where);
  check.finite(f.hc2, "HC2", where);
}

void print_warnings(const std::vector<std::string>& warnings) {
  for (const std::string& w : warnings) app::warn(w);
}

void write_warnings_attribute(io::Hdf5File& h5, const std::vector<std::string>& warnings) {
  std::string text;
  for (const std::string& w : warnings) text += (text.empty() ? "" : "\n") + w;
  h5.write_string_attribute("/", "warnings", text);
}

void write_critical_fields_hdf5(io::Hdf5File& h5, const std::string& group,
                                const CriticalFields& f) {
  h5.write_int_attribute(group, "hysteresis", f.hysteresis ? 1 : 0);
  h5.write_number_attribute(group, "HC1_T", f.hc1);
  h5.write_number_attribute(group, "HC2_T", f.hc2);
  h5.write_number_attribute(group, "dH_T", f.delta());
  h5.write_number_attribute(group, "uncertainty_T", f.uncertainty);
  h5.write_int_attribute(group, "valid", f.valid() ? 1 : 0);
  h5.write_int_attribute(group, "converged", f.converged ? 1 : 0);
  h5.write_string_attribute(group, "problem", f.problem);
}

void check_critical_fields_valid(app::ResultCheck& check, const std::string& where,
                                 const CriticalFields& f) {
  if (!f.valid()) check.flag("H_C1/H_C2", where + ": " + f.problem);
}

void describe_pair(app::InfoReport& report, const std::string& section, const PairSetup& setup) {
  const PairSystem p = setup.system();
  const SphereMaterial& m = p.material;
  report.add(section, "radius", m.radius, "m");
  report.add(section, "volume", m.volume(), "m^3", "V = 4/3 pi R^3");
  report.add(section, "saturation_magnetization", m.saturation_magnetization, "A/m");
  report.add(section, "susceptibility", m.susceptibility, "");
  report.add(section, "magnetic_energy_scale", m.magnetic_energy_scale(), "J",
             "mu0 Ms^2 V, prefactor of eq. 2.3");
  report.add_text(section, "spring_model",
                  setup.model == SpringModel::single ? "single (eq. 2.3)" : "three (eq. 2.4)");
  report.add_text(section, "stiffness_source", setup.stiffness.describe());
  report.add(section, "rest_separation", setup.rest_separation, "m", "S0");
  const double k_eq =
      setup.model == SpringModel::single ? p.springs.k12 : p.springs.k12 + 0.5 * p.springs.k0;
  if (setup.model == SpringModel::single) {
    report.add(section, "k", p.springs.k12, "N/m");
  } else {
    report.add(section, "k0", p.springs.k0, "N/m");
    report.add(section, "k12", p.springs.k12, "N/m");
    report.add(section, "k0_over_k12", p.springs.k0 / p.springs.k12, "");
  }
  report.add(section, "equivalent_single_k", k_eq, "N/m", "k0/2 + k12 (axial response)");
  report.add(section, "youngs_modulus_chapter2",
             youngs_from_spring_chapter2(k_eq, m.radius, setup.rest_separation), "Pa",
             "E = k S0 / (pi R^2)");
  report.add(section, "youngs_modulus_chapter3",
             youngs_from_spring_chapter3(k_eq, m.radius, setup.rest_separation), "Pa",
             "E = 2 k S0 / (pi D^2)");
  const double threshold = clustering_threshold_separation(m, k_eq);
  report.add(section, "clustering_threshold_S0", threshold, "m",
             "eq. 2.10 with the equivalent k (field along the axis)");
  report.add(section, "clustering_threshold_k",
             clustering_threshold_stiffness(m, setup.rest_separation), "N/m",
             "eq. 2.10 solved for k at this S0");
  report.add_text(section, "eq_2_10_predicts",
                  setup.rest_separation < threshold ? "clustering (hysteresis along the axis)"
                                                    : "no clustering");
  report.add_text(section, "penalty", p.penalty.kind == PenaltyKind::tanh ? "tanh" : "wca");
  report.add(section, "penalty_e_max", p.penalty.e_max, "J");
  if (p.penalty.kind == PenaltyKind::tanh) {
    report.add(section, "penalty_delta", p.penalty.delta, "1/m");
  } else {
    report.add(section, "penalty_r_min", p.penalty.r_min, "m");
    report.add(section, "penalty_r_cut", p.penalty.r_cut, "m");
  }
  report.add(section, "contact_separation", contact_separation(p.penalty, m.radius), "m",
             "clustered below this centre distance");
  const SweepOptions& sw = setup.sweep;
  report.add(section, "field_max", sw.b_max, "T");
  report.add(section, "field_step", sw.b_step, "T");
  report.add(section, "field_angle", sw.theta_h_deg, "deg",
             setup.model == SpringModel::single && sw.theta_h_deg != 0.0 && sw.theta_h_deg != 90.0
                 ? "single spring: the axis is held fixed (no rotational restoring force)"
                 : "");
  report.add(section, "reduced_field_max", reduced_field(sw.b_max, m.saturation_magnetization), "",
             "h = H/Ms at field_max");
  report.add_integer(section, "steps_per_loop", static_cast<std::int64_t>(sweep_points(sw).size()));
  report.add(section, "critical_field_tolerance", setup.critical_field_tolerance, "T");
  report.add_text(section, "relaxation",
                  sw.relax.method == RelaxMethod::newton
                      ? "Newton (polar coordinates, exact gradient)"
                      : "nonlinear conjugate gradients (Section 2.4, reference)");
}

// Zero-field equilibrium along the axis: m = 0 at B = 0 (linear law), so only the springs and
// the penalty act: (k12 + k0/2)(S - S0) + dP/dS = 0 (eqs. 2.3-2.4, the anchors after removing
// the centre of mass), solved by bisection between S0 and where the penalty lets go.
double zero_field_separation(const PairSystem& p) {
  const double s0 = p.springs.rest_separation;
  const double k =
      p.springs.k12 + (p.springs.model == SpringModel::three ? 0.5 * p.springs.k0 : 0.0);
  auto force = [&](double s) {
    return k * (s - s0) + overlap_penalty(p.penalty, p.material.radius, s).derivative;
  };
  const double f0 = force(s0);
  if (f0 == 0.0) return s0;
  // Pushed out: the root lies in (S0, r_cut] (at r_cut itself if the force jumps there).
  // Pulled in (the attractive tail of a WCA with r_cut past its minimum): in [r_lj, S0).
  double lo = f0 < 0.0 ? s0 : std::pow(2.0, 1.0 / 6.0) * p.penalty.r_min;
  double hi = f0 < 0.0 ? std::max(s0, p.penalty.r_cut) : s0;
  if (f0 < 0.0 && force(hi) < 0.0) return hi;
  for (int i = 0; i < 200 && hi - lo > 1e-15 * hi; ++i) {
    const double mid = 0.5 * (lo + hi);
    (force(mid) < 0.0 ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

std::string wca_cutoff_warning(const std::string& key, const std::vector<double>& separations,
                               const PairSetup& setup) {
  if (setup.penalty.kind != PenaltyKind::wca) return {};
  std::vector<double> inside;
  for (const double s0 : separations) {
    if (s0 < setup.penalty.r_cut) inside.push_back(s0);
  }
  if (inside.empty()) return {};
  const double used = zero_field_separation(setup.system_at(inside.front()));
  if (std::abs(used - inside.front()) <= 1e-9 * inside.front()) return {};
  std::string given = fmt::format("{} = {:.6g} m lies", key, inside.front());
  if (separations.size() > 1 && inside.size() == 1) {
    given = fmt::format("{}: 1 of the {} separations ({:.6g} m) lies", key, separations.size(),
                        inside.front());
  } else if (separations.size() > 1) {
    given = fmt::format("{}: {} of the {} separations ({:.6g} ... {:.6g} m) lie", key,
                        inside.size(), separations.size(), inside.front(), inside.back());
  }
  return fmt::format(
      "{} inside the WCA cut-off penalty.r_cut = {:.6g} m, where the penalty acts: at zero field "
      "the pair sits at S = {:.6g} m instead of S0 = {:.6g} m{}",
      given, setup.penalty.r_cut, used, inside.front(),
      inside.size() == 1 ? "" : " (the first of them)");
}

std::size_t unconverged_states(const HysteresisLoop& loop) {
  return static_cast<std::size_t>(std::count_if(loop.states.begin(), loop.states.end(),
                                                [](const PairState& s) { return !s.converged; }));
}

}  // namespace mresim::pair::runs
