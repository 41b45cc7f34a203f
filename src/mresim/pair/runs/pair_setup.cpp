#include "mresim/pair/runs/pair_setup.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <utility>

#include "mresim/core/constants.hpp"
#include "mresim/pair/overlap_penalty.hpp"
#include "mresim/pair/stiffness.hpp"

namespace mresim::pair::runs {

using config::Range;
using config::TableReader;

std::string StiffnessSource::describe() const {
  switch (kind) {
    case Kind::spring_constant:
      return "spring constant k";
    case Kind::three_spring_constants:
      return "spring constants k0, k12";
    case Kind::shear_modulus:
      return "shear modulus (Puljiz, eqs. 2.8-2.9)";
    case Kind::youngs_modulus:
      return chapter3_cylinder ? "Young's modulus, Chapter 3 cylinder (k = E pi D^2 / (2 S0))"
                               : "Young's modulus, Chapter 2 cylinder (k = E pi R^2 / S0)";
  }
  return {};
}

PairSystem PairSetup::system() const { return system_at(rest_separation); }

PairSystem PairSetup::system_at(double s0) const {
  PairSystem p;
  p.material = material;
  p.penalty = penalty;
  p.springs.model = model;
  p.springs.rest_separation = s0;
  const double r = material.radius;
  switch (stiffness.kind) {
    case StiffnessSource::Kind::spring_constant:
      p.springs.k12 = stiffness.k;
      break;
    case StiffnessSource::Kind::three_spring_constants:
      p.springs.k12 = stiffness.k12;
      p.springs.k0 = stiffness.k0;
      break;
    case StiffnessSource::Kind::shear_modulus: {
      const PuljizStiffness k = puljiz_stiffness(stiffness.modulus, r, s0);
      if (model == SpringModel::three) {
        p.springs.k12 = k.k12;
        p.springs.k0 = k.k0;
      } else {
        p.springs.k12 = k.equivalent_single();
      }
      break;
    }
    case StiffnessSource::Kind::youngs_modulus:
      p.springs.k12 = stiffness.chapter3_cylinder
                          ? spring_from_youngs_chapter3(stiffness.modulus, r, s0)
                          : spring_from_youngs_chapter2(stiffness.modulus, r, s0);
      break;
  }
  return p;
}

namespace {

// Lengths handled by the solver in units of R are squared and raised to the 7th power (the
// dipole gradient); beyond this ratio to R their squares approach the largest double.
constexpr double kMaxReducedLength = 1e100;
// Bound on field.max in units of the saturation field mu0 Ms (validate_field_magnitude).
constexpr double kMaxReducedField = 1e6;
constexpr double kSmallest = std::numeric_limits<double>::min();
constexpr double kLargest = std::numeric_limits<double>::max();

const std::vector<std::string> kStiffnessKeys{"k", "k0", "k12", "shear_modulus", "youngs_modulus"};

void read_material(const TableReader& t, SphereMaterial& m) {
  m.radius = t.number_or("radius", m.radius, Range::positive(), "m");
  m.saturation_magnetization =
      t.number_or("saturation_magnetization", m.saturation_magnetization, Range::positive(), "A/m");
  m.susceptibility = t.number_or("susceptibility", m.susceptibility, Range::positive(), "");
}

// Reads the stiffness keys present in [springs]; returns false if none is given.
bool read_stiffness(const TableReader& t, SpringModel model, StiffnessSource& out) {
  std::vector<std::string> given;
  for (const std::string& key : kStiffnessKeys) {
    if (t.has(key)) given.push_back(key);
  }
  // Mark the convention key as known whether or not it is used, and validate it.
  const std::string convention =
      t.choice_or("youngs_convention", "chapter2", {"chapter2", "chapter3"});
  if (given.empty()) return false;
  const bool pair_of_constants = given.size() == 2 && given[0] == "k0" && given[1] == "k12";
  if (given.size() > 1 && !pair_of_constants) {
    t.fail(given[1], t.value_text(given[1]),
           fmt::format("give one stiffness: k, k0 and k12, shear_modulus or youngs_modulus "
                       "(also given: {})",
                       given[0]));
  }
  const std::string& key = given[0];
  StiffnessSource s;
  if (key == "k") {
    if (model == SpringModel::three) {
      t.fail("k", t.value_text("k"),
             "the three-spring model takes k0 and k12 (or shear_modulus); k is the single spring");
    }
    s.kind = StiffnessSource::Kind::spring_constant;
    s.k = t.number("k", Range::positive(), "N/m");
  } else if (key == "k0" || key == "k12") {
    if (model == SpringModel::single) {
      t.fail(key, t.value_text(key), "k0 and k12 belong to the three-spring model; use k");
    }
    if (!pair_of_constants) t.fail(key, t.value_text(key), "give both k0 and k12");
    s.kind = StiffnessSource::Kind::three_spring_constants;
    s.k0 = t.number("k0", Range::positive(), "N/m");
    s.k12 = t.number("k12", Range::positive(), "N/m");
  } else if (key == "shear_modulus") {
    s.kind = StiffnessSource::Kind::shear_modulus;
    s.modulus = t.number("shear_modulus", Range::positive(), "Pa");
  } else {
    if (model == SpringModel::three) {
      t.fail("youngs_modulus", t.value_text("youngs_modulus"),
             "the three-spring model takes k0 and k12 or shear_modulus");
    }
    s.kind = StiffnessSource::Kind::youngs_modulus;
    s.modulus = t.number("youngs_modulus", Range::positive(), "Pa");
    s.chapter3_cylinder = convention == "chapter3";
  }
  out = s;
  return true;
}

// [penalty]: the type falls back to the current one; switching type restores that type's
// defaults (Section 2.4: tanh E_max = 100, delta = 1e-2; WCA E_max = 0.01, r_min = 2R).
void read_penalty(const TableReader& t, PairSetup& s) {
  const std::string current = s.penalty.kind == PenaltyKind::tanh ? "tanh" : "wca";
  const std::string kind = t.choice_or("type", current, {"tanh", "wca"});
  if (kind != current) {
    s.penalty = kind == "tanh" ? OverlapPenalty::tanh_default(s.material.radius)
                               : OverlapPenalty::wca_default(s.material.radius);
  }
  OverlapPenalty& p = s.penalty;
  p.e_max = t.number_or("e_max", p.e_max, Range::positive(), "J");
  if (p.kind == PenaltyKind::tanh) {
    p.delta = t.number_or("delta", p.delta, Range::positive(), "1/m");
    return;
  }
  const bool r_min_given = t.has("r_min");
  p.r_min = t.number_or("r_min", p.r_min, Range::positive(), "m");
  // Without an explicit cut-off the WCA stays purely repulsive: r_cut = 2^(1/6) r_min.
  const double default_cut = r_min_given ? std::pow(2.0, 1.0 / 6.0) * p.r_min : p.r_cut;
  p.r_cut = t.number_or("r_cut", default_cut, Range::positive(), "m");
}

// Fails on `table`.`key` of `scope`, naming the full dotted key even when `scope` does not
// contain that table (a [[case]] inheriting the value from the root).
[[noreturn]] void fail_in(const TableReader& scope, const std::string& table,
                          const std::string& key, double value, const std::string& what) {
  if (scope.has(table)) scope.table(table).fail(key, value, what);
  const std::string prefix = scope.path().empty() ? "" : scope.path() + ".";
  throw config::ConfigError(fmt::format("{}{}.{} = {}: {}", prefix, table, key, value, what));
}

// A positive, finite double that is not subnormal (and not 0 after underflow).
bool normal_positive(double x) { return std::isfinite(x) && x >= kSmallest; }

// The field itself, before anything derived from it (the critical-field tolerance, the reduced
// scales): at most kMaxReducedField saturation fields mu0 Ms. The pair saturates at a few
// mu0 Ms; a sweep far beyond that only makes the Zeeman energy swamp every other term (the
// solver failed from about 1e27 mu0 Ms on: "coincident sphere centres", invalid critical fields).
void validate_field_magnitude(const TableReader& scope, const PairSetup& s) {
  const double limit = kMaxReducedField * kMu0 * s.material.saturation_magnetization;
  if (s.sweep.b_max > limit) {
    fail_in(scope, "field", "max", s.sweep.b_max,
            fmt::format("must be <= {:.0e} mu0 Ms = {:.6g} T at Ms = {:.6g} A/m (the pair is "
                        "saturated long before; far beyond, the Zeeman energy swamps every other "
                        "term of the solver)",
                        kMaxReducedField, limit, s.material.saturation_magnetization));
  }
}

void read_field(const TableReader& scope, const TableReader& t, PairSetup& s) {
  SweepOptions& sweep = s.sweep;
  sweep.b_max = t.number_or("max", sweep.b_max, Range::positive(), "T");
  validate_field_magnitude(scope, s);  // before step and tolerance: they are relative to max
  sweep.b_step = t.number_or("step", sweep.b_step, Range::positive(), "T");
  sweep.theta_h_deg = t.number_or("angle", sweep.theta_h_deg, Range::between(0.0, 90.0), "deg");
  const double steps = sweep.b_max / sweep.b_step;
  if (std::abs(steps - std::round(steps)) > 1e-6 * steps) {
    t.fail("max", sweep.b_max,
           fmt::format("must be a whole number of field.step = {} T (the sweep visits "
                       "0, +max, -max exactly)",
                       sweep.b_step));
  }
  if (std::round(steps) > 1e6) {
    t.fail("step", sweep.b_step, "must give at most 1e6 steps up to field.max");
  }
}

// The energy unit mu0 Ms^2 V and the length unit R of the solver (pair_energy.hpp) must be
// normal doubles, or every reduced quantity becomes 0, inf or NaN.
void validate_material_scales(const TableReader& scope, const SphereMaterial& m) {
  const double shape = 4.0 / 3.0 * std::numbers::pi;
  const double v = m.volume();
  if (!normal_positive(v)) {
    fail_in(scope, "material", "radius", m.radius,
            fmt::format("gives the sphere volume V = 4/3 pi R^3 = {:.3g} m^3, outside the range "
                        "of doubles; R must lie in [{:.3g}, {:.3g}] m",
                        v, std::cbrt(kSmallest / shape), std::cbrt(kLargest / shape)));
  }
  const double scale = m.magnetic_energy_scale();
  if (!normal_positive(scale)) {
    fail_in(scope, "material", "saturation_magnetization", m.saturation_magnetization,
            fmt::format("gives the magnetic energy scale mu0 Ms^2 V = {:.3g} J, outside the range "
                        "of doubles; at R = {:.6g} m Ms must lie in [{:.3g}, {:.3g}] A/m",
                        scale, m.radius, std::sqrt(kSmallest / std::min(v, 1.0)) / std::sqrt(kMu0),
                        std::sqrt(kLargest / std::max(v, 1.0)) / std::sqrt(kMu0)));
  }
}

// The key that sets the spring constants, for messages.
std::string stiffness_key(const StiffnessSource& s) {
  switch (s.kind) {
    case StiffnessSource::Kind::spring_constant:
      return "k";
    case StiffnessSource::Kind::three_spring_constants:
      return "k12";
    case StiffnessSource::Kind::shear_modulus:
      return "shear_modulus";
    case StiffnessSource::Kind::youngs_modulus:
      return "youngs_modulus";
  }
  return "k";
}

// The spring energy scale k S0^2 and the spring constants in solver units k R^2 / (mu0 Ms^2 V).
void validate_spring_scales(const TableReader& scope, const PairSetup& s, const PairSystem& p) {
  const double scale = p.material.magnetic_energy_scale();
  const double r = p.material.radius;
  const std::string key = stiffness_key(s.stiffness);
  const double value = s.stiffness.kind == StiffnessSource::Kind::spring_constant ? s.stiffness.k
                       : s.stiffness.kind == StiffnessSource::Kind::three_spring_constants
                           ? s.stiffness.k12
                           : s.stiffness.modulus;
  for (const double k : {p.springs.k12, p.springs.k0}) {
    const double energy = k * s.rest_separation * s.rest_separation;
    if (!std::isfinite(k) || !std::isfinite(energy) || !std::isfinite(k * r * r / scale)) {
      fail_in(scope, "springs", key, value,
              fmt::format("gives the spring constant {:.3g} N/m and the spring energy scale "
                          "k S0^2 = {:.3g} J, which overflow next to the magnetic energy scale "
                          "mu0 Ms^2 V = {:.3g} J",
                          k, energy, scale));
    }
  }
}

// Field, penalty and springs in the solver's units (lengths in R, energies in mu0 Ms^2 V).
void validate_reduced_scales(const TableReader& scope, const PairSetup& s) {
  const SphereMaterial& m = s.material;
  const double scale = m.magnetic_energy_scale();
  const double h = reduced_field(s.sweep.b_max, m.saturation_magnetization);
  if (!std::isfinite(h) || !std::isfinite(2.0 * h * scale)) {
    fail_in(scope, "field", "max", s.sweep.b_max,
            fmt::format("gives the reduced field H/Ms = {:.3g} and the field energy scale "
                        "2 mu0 Ms H V = {:.3g} J, which overflow",
                        h, 2.0 * h * scale));
  }
  const OverlapPenalty& p = s.penalty;
  if (!std::isfinite(p.e_max / scale)) {
    fail_in(scope, "penalty", "e_max", p.e_max,
            fmt::format("is {:.3g} times the magnetic energy scale mu0 Ms^2 V = {:.3g} J, which "
                        "overflows",
                        p.e_max / scale, scale));
  }
  if (p.kind == PenaltyKind::tanh) {
    const double slope = p.e_max / (scale * p.delta * m.radius);  // dE/dS at u = 0, solver units
    if (!std::isfinite(slope) || !normal_positive(p.delta * m.radius)) {
      fail_in(scope, "penalty", "delta", p.delta,
              fmt::format("gives the barrier slope E_max / (delta R) = {:.3g} mu0 Ms^2 V / R, "
                          "which overflows",
                          slope));
    }
  } else {
    for (const auto& [key, length] : {std::pair{"r_min", p.r_min}, std::pair{"r_cut", p.r_cut}}) {
      if (length > kMaxReducedLength * m.radius || !normal_positive(length / m.radius)) {
        fail_in(scope, "penalty", key, length,
                fmt::format("must lie in [{:.3g}, {:.3g}] m (lengths are computed in units of R "
                            "and raised to the 12th power relative to each other)",
                            kSmallest * m.radius, kMaxReducedLength * m.radius));
      }
    }
  }
  validate_spring_scales(scope, s, s.system());
}

}  // namespace

PairSetup read_pair_setup(const TableReader& scope, const PairSetup& base, bool is_root,
                          bool stiffness_required) {
  PairSetup s = base;
  if (auto t = scope.optional_table("material")) read_material(*t, s.material);

  std::optional<TableReader> springs = is_root ? std::optional<TableReader>(scope.table("springs"))
                                               : scope.optional_table("springs");
  bool model_changed = false;
  if (springs) {
    const std::string model = springs->choice_or(
        "model", s.model == SpringModel::single ? "single" : "three", {"single", "three"});
    const SpringModel chosen = model == "single" ? SpringModel::single : SpringModel::three;
    model_changed = chosen != s.model;
    s.model = chosen;
    s.rest_separation =
        springs->number_or("rest_separation", s.rest_separation, Range::positive(), "m");
    const bool given = read_stiffness(*springs, s.model, s.stiffness);
    if (!given && stiffness_required && (is_root || model_changed)) {
      springs->fail(
          "model",
          springs->value_text("model").empty() ? "\"" + model + "\"" : springs->value_text("model"),
          "needs a stiffness: k (single), k0 and k12 (three), shear_modulus, or "
          "youngs_modulus (single)");
    }
  }
  // The three-spring model uses the WCA by default (Section 2.5.3), the single spring tanh;
  // the penalty geometry scales with the radius.
  if (is_root || model_changed || s.material.radius != base.material.radius) {
    s.penalty = s.model == SpringModel::three ? OverlapPenalty::wca_default(s.material.radius)
                                              : OverlapPenalty::tanh_default(s.material.radius);
  }
  if (auto t = scope.optional_table("penalty")) read_penalty(*t, s);
  if (auto t = scope.optional_table("field")) read_field(scope, *t, s);
  validate_field_magnitude(scope, s);  // also when a [[case]] changes Ms but not the field
  if (auto t = scope.optional_table("solver")) {
    const std::string current =
        s.sweep.relax.method == RelaxMethod::newton ? "newton" : "conjugate_gradient";
    const std::string method = t->choice_or("method", current, {"newton", "conjugate_gradient"});
    s.sweep.relax.method =
        method == "newton" ? RelaxMethod::newton : RelaxMethod::conjugate_gradient;
    s.sweep.relax.max_iterations = static_cast<int>(
        t->integer_or("max_iterations", s.sweep.relax.max_iterations, Range::between(1, 10000000)));
  }
  if (auto t = scope.optional_table("critical_fields")) {
    s.critical_field_tolerance =
        t->number_or("tolerance", s.critical_field_tolerance, Range::positive(), "T");
    if (s.critical_field_tolerance >= s.sweep.b_step) {
      t->fail("tolerance", s.critical_field_tolerance,
              fmt::format("must be < field.step = {} T", s.sweep.b_step));
    }
    // Bisection cannot narrow a bracket below the spacing of doubles near the field; 1e-12 of
    // the swept range keeps well clear of it (about 1e4 ulps at field.max).
    const double finest = 1e-12 * s.sweep.b_max;
    if (s.critical_field_tolerance < finest) {
      t->fail("tolerance", s.critical_field_tolerance,
              fmt::format("must be in [{:g}, {:g}) T: at least 1e-12 x field.max (finer is below "
                          "what double precision resolves) and below field.step",
                          finest, s.sweep.b_step));
    }
  }
  validate_pair(scope, s);
  return s;
}

void require_separable(const TableReader& table, const std::string& key, double s0,
                       const SphereMaterial& material) {
  if (s0 <= 2.0 * material.radius) {
    table.fail(key, s0,
               fmt::format("every separation must be > 2R = {:.6g} m (the spheres would overlap)",
                           2.0 * material.radius));
  }
}

void require_separations(const TableReader& table, const std::string& axis,
                         const std::vector<double>& separations, const SphereMaterial& material) {
  const bool listed = table.has(axis + "_values");
  for (const double s0 : separations) {
    require_separable(table, listed ? axis + "_values" : axis + "_min", s0, material);
    if (s0 > kMaxReducedLength * material.radius) {
      table.fail(listed ? axis + "_values" : axis + "_max", listed ? s0 : separations.back(),
                 fmt::format("every separation must be <= {:.0e} R = {:.6g} m (lengths are "
                             "computed in units of R and squared)",
                             kMaxReducedLength, kMaxReducedLength * material.radius));
    }
  }
}

void validate_pair(const TableReader& scope, const PairSetup& s) {
  validate_material_scales(scope, s.material);
  const double contact = 2.0 * s.material.radius;
  if (s.rest_separation <= contact) {
    fail_in(scope, "springs", "rest_separation", s.rest_separation,
            fmt::format("must be > 2R = {:.6g} m (the spheres would overlap)", contact));
  }
  if (s.rest_separation > kMaxReducedLength * s.material.radius) {
    fail_in(scope, "springs", "rest_separation", s.rest_separation,
            fmt::format("must be <= {:.0e} R = {:.6g} m (lengths are computed in units of R "
                        "and squared)",
                        kMaxReducedLength, kMaxReducedLength * s.material.radius));
  }
  validate_reduced_scales(scope, s);
  if (s.penalty.kind == PenaltyKind::wca && s.penalty.r_cut <= s.penalty.r_min) {
    const TableReader penalty = scope.has("penalty") ? scope.table("penalty") : scope;
    penalty.fail("r_cut", s.penalty.r_cut,
                 fmt::format("must be > penalty.r_min = {:.6g} m", s.penalty.r_min));
  }
  // chi >= 3 S^3 / 2 at contact makes the linear law unstable (I - chi D singular): the pair
  // would magnetize itself at zero field.
  const double chi_limit = 1.5 * std::pow(contact / s.material.radius, 3);
  if (s.material.susceptibility >= chi_limit) {
    const TableReader material = scope.has("material") ? scope.table("material") : scope;
    material.fail("susceptibility", s.material.susceptibility,
                  fmt::format("must be < {:.6g}: above it two touching spheres magnetize each "
                              "other without a field (eq. 2.5 becomes singular)",
                              chi_limit));
  }
}

std::vector<PairSetup> read_pair_cases(const TableReader& root) {
  PairSetup base;
  base.label = root.optional_table("run") ? root.table("run").string_or("title", "") : "";
  base = read_pair_setup(root, base, true);
  const std::vector<TableReader> cases = root.table_list("case");
  if (cases.empty()) return {base};
  std::vector<PairSetup> out;
  for (const TableReader& c : cases) {
    PairSetup s = read_pair_setup(c, base, false);
    s.label = c.string_or("label", "");
    if (s.label.empty()) c.fail("label", "\"\"", "each [[case]] needs a non-empty label");
    out.push_back(s);
  }
  return out;
}

}  // namespace mresim::pair::runs
