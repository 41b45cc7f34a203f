#include "mresim/pair/runs/pair_setup.hpp"

#include <fmt/format.h>

#include <cmath>

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

void read_field(const TableReader& t, SweepOptions& sweep) {
  sweep.b_max = t.number_or("max", sweep.b_max, Range::positive(), "T");
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
  if (auto t = scope.optional_table("field")) read_field(*t, s.sweep);
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

void validate_pair(const TableReader& scope, const PairSetup& s) {
  const double contact = 2.0 * s.material.radius;
  if (s.rest_separation <= contact) {
    const TableReader springs = scope.has("springs") ? scope.table("springs") : scope;
    springs.fail("rest_separation", s.rest_separation,
                 fmt::format("must be > 2R = {:.6g} m (the spheres would overlap)", contact));
  }
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
