// Reading the 3D run file (docs/run-files-3d.md): every key read here, in one place, with its
// unit, default and range; checks that involve several keys fail on the key a user would change.

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include "mresim/config/evenly_spaced.hpp"
#include "mresim/core/constants.hpp"
#include "mresim/mess/lattice/stiffness.hpp"
#include "mresim/mess/protocols/protocol.hpp"
#include "mresim/mess/run_file/mess_spec.hpp"
#include "mresim/mess/run_file/read_analysis.hpp"

namespace mresim::mess_config {

using config::ConfigError;
using config::Range;
using config::TableReader;

namespace {

constexpr double kDegree = std::numbers::pi / 180.0;

const std::vector<std::string> kPlacements{"regular",
                                           "regular_noisy",
                                           "regular_anisotropic",
                                           "regular_anisotropic_noisy",
                                           "anisotropic_regular",
                                           "anisotropic_regular_noisy",
                                           "by_hand",
                                           "chain",
                                           "helix",
                                           "none"};

// The table reader returns vectors as plain arrays (config/ does not depend on Eigen).
Eigen::Vector3d to_vector(const std::array<double, 3>& v) { return {v[0], v[1], v[2]}; }
std::optional<Eigen::Vector3d> to_vector(const std::optional<std::array<double, 3>>& v) {
  if (!v) return std::nullopt;
  return to_vector(*v);
}
std::vector<Eigen::Vector3d> to_vectors(const std::vector<std::array<double, 3>>& list) {
  std::vector<Eigen::Vector3d> out;
  out.reserve(list.size());
  for (const auto& v : list) out.push_back(to_vector(v));
  return out;
}

// The value as written, or `fallback` (a default) when the key is absent.
std::string text_or(const TableReader& t, std::string_view key, const std::string& fallback) {
  const std::string text = t.value_text(key);
  return text.empty() ? fallback : text;
}

// A required key that is absent; names a likely misspelling of it the file has (the same hint
// as TableReader's own "missing key" messages).
[[noreturn]] void missing(const TableReader& t, std::string_view key, std::string_view what) {
  throw ConfigError(
      fmt::format("missing key '{}' ({}){}", t.path(key), what, t.misspelling_hint(key)));
}

// The same, for a key that another key needs: "field.steps = (missing): field.max needs ...".
[[noreturn]] void needed(const TableReader& t, std::string_view key, const std::string& what) {
  t.fail(key, "(missing)", what + t.misspelling_hint(key));
}

// ------------------------------------------------------------------------------------ [model]

void read_model(const std::optional<TableReader>& model, MessSpec& s) {
  lattice::LatticeSpec& l = s.lattice;
  if (!model) return;  // every key has a default
  const TableReader& t = *model;
  s.profile = &mess::model_profile(t.choice_or("profile", "physical", mess::model_profile_names()));
  s.profile->apply_to(l);
  l.youngs_modulus = t.number_or("youngs_modulus", 9.0e3, Range::positive(), "Pa");
  l.poisson_ratio = t.number_or("poisson_ratio", 0.47, Range::open(-1.0, 0.5), "");
  if (l.poisson_ratio <= s.profile->poisson_ratio_lower_limit) {
    t.fail("poisson_ratio", t.value_text("poisson_ratio"),
           fmt::format(R"(must be > {:.4f} with profile = "{}": {}; use profile = "physical")",
                       s.profile->poisson_ratio_lower_limit, s.profile->name,
                       s.profile->poisson_ratio_limit_reason));
  }
  l.stiffness_ratio = t.number_or("stiffness_ratio", 1.0, Range::positive(), "");
  l.discretization_order =
      static_cast<int>(t.integer_or("discretization_order", 5, Range::between(1, 1000)));
  l.polymer_density =
      t.number_or("polymer_density", lattice::kPolymerDensity, Range::positive(), "kg/m^3");
}

// -------------------------------------------------------------------------------- [particles]

struct PlacementKey {
  const char* key;
  const char* used_by;
};
// Every placement key, and the placements that use it (for "not used by" messages).
const std::vector<PlacementKey> kPlacementKeys{
    {"volume_fraction", "the regular placements"},
    {"count_per_axis", "the regular placements"},
    {"anisotropy_factor", "regular_anisotropic(_noisy)"},
    {"noise_seed", "regular_noisy and regular_anisotropic_noisy"},
    {"positions", "by_hand"},
    {"count", "chain and helix"},
    {"separation", "chain"},
    {"axis", "chain"},
    {"centre", "chain and helix"},
    {"helix_radius", "helix"},
    {"axial_separation", "helix"},
    {"angle_step", "helix"},
};

void reject_foreign_keys(const TableReader& t, const std::string& placement,
                         const std::vector<std::string>& used) {
  for (const auto& [key, used_by] : kPlacementKeys) {
    if (std::find(used.begin(), used.end(), key) != used.end() || !t.has(key)) continue;
    t.fail(key, t.value_text(key),
           fmt::format("not used by placement = \"{}\" (only by {})", placement, used_by));
  }
}

std::array<double, 3> read_anisotropy(const TableReader& t) {
  if (t.is_array("anisotropy_factor")) {
    return *t.optional_vector3("anisotropy_factor", Range::positive(), "");
  }
  const auto f = t.optional_number("anisotropy_factor", Range::positive(), "");
  if (!f) {
    missing(t, "anisotropy_factor",
            "f, giving relative sizes (1/sqrt(f), 1/sqrt(f), f), or [fx, fy, fz]");
  }
  const double side = 1.0 / std::sqrt(*f);
  return {side, side, *f};
}

lattice::BoxSpec read_box(const TableReader& root, const mess::ModelProfile& profile) {
  const TableReader box = root.table("box");
  lattice::BoxSpec b;
  const auto size = box.optional_vector3("size", Range::positive(), "m");
  if (!size) missing(box, "size", "[Lx, Ly, Lz], m");
  b.lengths = to_vector(*size);
  b.rounding = box.enumeration_or("rounding", profile.default_box_rounding,
                                  {{"nearest", lattice::BoxRounding::nearest},
                                   {"seed_floor_divide", lattice::BoxRounding::seed_floor_divide}});
  return b;
}

void read_placement(const TableReader& root, const TableReader& t, MessSpec& s) {
  const std::string name = t.choice("placement", kPlacements);
  s.placement_kind = lattice::parse_placement_kind(name);
  using Kind = lattice::PlacementKind;
  const Kind kind = s.placement_kind;
  const bool regular = kind == Kind::regular || kind == Kind::regular_noisy ||
                       kind == Kind::regular_anisotropic || kind == Kind::regular_anisotropic_noisy;

  if (regular) {
    const bool anisotropic =
        kind == Kind::regular_anisotropic || kind == Kind::regular_anisotropic_noisy;
    const bool noisy = kind == Kind::regular_noisy || kind == Kind::regular_anisotropic_noisy;
    std::vector<std::string> used{"volume_fraction", "count_per_axis"};
    if (anisotropic) used.emplace_back("anisotropy_factor");
    if (noisy) used.emplace_back("noise_seed");
    reject_foreign_keys(t, name, used);
    if (root.has("box")) {
      root.fail("box", root.value_text("box"),
                fmt::format(
                    "placement = \"{}\" sizes the box from particles.volume_fraction "
                    "(eqs. 4.50-4.52); [box] is only read with placement = \"by_hand\", \"none\", "
                    "\"chain\" or \"helix\"",
                    name));
    }
    lattice::RegularPlacement r;
    r.volume_fraction = t.number("volume_fraction", Range::open(0.0, 1.0), "");
    const auto counts = t.optional_integer3("count_per_axis", Range::between(1, 10000));
    if (!counts) missing(t, "count_per_axis", "[nx, ny, nz], particles along x, y and z");
    for (int a = 0; a < 3; ++a) r.particles_along_axes[a] = static_cast<int>((*counts)[a]);
    r.anisotropic = anisotropic;
    if (anisotropic) r.anisotropy_factor = read_anisotropy(t);
    r.noisy = noisy;
    if (noisy) {
      r.noise_seed = static_cast<std::uint64_t>(t.integer("noise_seed", Range::non_negative()));
    }
    s.requested_volume_fraction = r.volume_fraction;
    s.lattice.placement = r;
    return;
  }

  if (kind == Kind::none) {
    // The particle-free block (the polymer reference of the MR effect): radius and
    // discretization_order still set l_e (eq. 4.49); the box is [box]'s.
    reject_foreign_keys(t, name, {});
    lattice::ByHandPlacement h;
    h.box = read_box(root, *s.profile);
    s.box = h.box;
    s.lattice.placement = h;
  } else if (kind == Kind::by_hand) {
    reject_foreign_keys(t, name, {"positions"});
    lattice::ByHandPlacement h;
    h.box = read_box(root, *s.profile);
    const auto positions = t.optional_vector3_list("positions", Range::any(), "m", 1);
    if (!positions) missing(t, "positions", "[[x, y, z], ...], particle centres in m");
    h.positions = to_vectors(*positions);
    s.box = h.box;
    s.lattice.placement = h;
  } else if (kind == Kind::chain) {
    reject_foreign_keys(t, name, {"count", "separation", "axis", "centre"});
    lattice::ChainPlacement c;
    c.box = read_box(root, *s.profile);
    c.count = static_cast<int>(t.integer_or("count", 2, Range::between(1, 100000)));
    c.separation = t.number("separation", Range::positive(), "m");
    c.axis = t.enumeration_or("axis", 2, {{"x", 0}, {"y", 1}, {"z", 2}});
    c.centre = to_vector(t.optional_vector3("centre", Range::any(), "m"));
    s.box = c.box;
    s.lattice.placement = c;
  } else {
    reject_foreign_keys(t, name,
                        {"count", "helix_radius", "axial_separation", "angle_step", "centre"});
    lattice::HelixPlacement h;
    h.box = read_box(root, *s.profile);
    h.count = static_cast<int>(t.integer_or("count", 8, Range::between(1, 100000)));
    h.radius = t.number("helix_radius", Range::non_negative(), "m");
    h.axial_separation = t.number_or("axial_separation", 5.0e-6, Range::any(), "m");
    h.angle_step = kDegree * t.number_or("angle_step", 45.0, Range::any(), "deg");
    h.centre = to_vector(t.optional_vector3("centre", Range::any(), "m"));
    s.box = h.box;
    s.lattice.placement = h;
  }
}

// "particles 0 and 1 overlap: ..." -> 1; "... particle 2 at ..." -> 2; the particle the lattice
// names last (the later of an overlapping pair).
std::optional<std::size_t> particle_named_in(const std::string& message) {
  for (const std::string& word : {std::string("particles "), std::string("particle ")}) {
    const std::size_t at = message.find(word);
    if (at == std::string::npos) continue;
    std::size_t i = at + word.size();
    std::optional<std::size_t> last;
    while (i < message.size() && std::isdigit(static_cast<unsigned char>(message[i]))) {
      std::size_t value = 0;
      while (i < message.size() && std::isdigit(static_cast<unsigned char>(message[i]))) {
        value = 10 * value + static_cast<std::size_t>(message[i] - '0');
        ++i;
      }
      last = value;
      if (message.compare(i, 5, " and ") == 0) i += 5;
    }
    if (last) return last;
  }
  return std::nullopt;
}

std::string without_placement_prefix(std::string message) {
  for (const char* prefix : {"by_hand placement: ", "chain placement: ", "helix placement: "}) {
    if (message.rfind(prefix, 0) == 0) return message.substr(std::string(prefix).size());
  }
  return message;
}

constexpr const char* kDoNotFit =
    " (the particles do not fit at this volume fraction and discretization order)";

// Sizes the box and places the particles; a failure becomes a ConfigError on the key a user
// would change.
void derive_checked(const TableReader& root, const TableReader& t, MessSpec& s) {
  using Kind = lattice::PlacementKind;
  const Kind kind = s.placement_kind;
  const double l_e =
      lattice::element_length(s.lattice.particle_radius, s.lattice.discretization_order);

  // 1. The box alone.
  if (const auto* r = std::get_if<lattice::RegularPlacement>(&s.lattice.placement)) {
    const std::string key = r->anisotropic ? "anisotropy_factor" : "volume_fraction";
    lattice::GridShape shape;
    try {
      shape = lattice::box_from_volume_fraction(
                  s.lattice.particle_radius, l_e, r->volume_fraction, r->particles_along_axes,
                  r->anisotropic ? r->anisotropy_factor : std::array<double, 3>{1.0, 1.0, 1.0})
                  .shape;
    } catch (const std::invalid_argument& e) {
      t.fail(key, t.value_text(key), e.what());
    }
    if (shape.node_count() > kMaxNodes) {
      t.fail("volume_fraction", t.value_text("volume_fraction"),
             fmt::format("gives {} x {} x {} = {} nodes at l_e = {:.6g} m; at most {} are "
                         "supported",
                         shape.nx(), shape.ny(), shape.nz(), shape.node_count(), l_e, kMaxNodes));
    }
  } else {
    const TableReader box = root.table("box");
    lattice::GridShape shape;
    try {
      shape = lattice::shape_of_box(*s.box, l_e);
    } catch (const std::invalid_argument& e) {
      box.fail("size", box.value_text("size"), e.what());
    }
    if (shape.node_count() > kMaxNodes) {
      box.fail("size", box.value_text("size"),
               fmt::format("gives {} x {} x {} = {} nodes at l_e = {:.6g} m; at most {} are "
                           "supported",
                           shape.nx(), shape.ny(), shape.nz(), shape.node_count(), l_e, kMaxNodes));
    }
  }

  // 2. The particles in it.
  try {
    s.geometry = derive_geometry(s.lattice);
    return;
  } catch (const std::invalid_argument& e) {
    const std::string message = without_placement_prefix(e.what());
    const bool overlap = message.find(" overlap") != std::string::npos;
    switch (kind) {
      case Kind::none:
        break;  // only the box can fail, which step 1 reports
      case Kind::by_hand: {
        const auto p = particle_named_in(message);
        const auto& positions = std::get<lattice::ByHandPlacement>(s.lattice.placement).positions;
        if (p && *p < positions.size()) {
          t.fail(fmt::format("positions[{}]", *p),
                 config::vector_text({positions[*p][0], positions[*p][1], positions[*p][2]}),
                 message);
        }
        t.fail("positions", t.value_text("positions"), message);
      }
      case Kind::chain:
        if (!overlap && t.has("centre")) t.fail("centre", t.value_text("centre"), message);
        if (!overlap) {
          const TableReader box = root.table("box");
          box.fail("size", box.value_text("size"), message);
        }
        t.fail("separation", t.value_text("separation"), message);
      case Kind::helix:
        if (overlap) {
          t.fail("axial_separation", text_or(t, "axial_separation", "5e-06 (default)"), message);
        }
        if (t.has("centre")) t.fail("centre", t.value_text("centre"), message);
        t.fail("helix_radius", t.value_text("helix_radius"), message);
      case Kind::regular_noisy:
      case Kind::regular_anisotropic_noisy: {
        // The noise made it fail if the same placement without noise is fine.
        lattice::LatticeSpec quiet = s.lattice;
        std::get<lattice::RegularPlacement>(quiet.placement).noisy = false;
        bool quiet_ok = true;
        try {
          (void)lattice::place_particles(quiet.placement, quiet.particle_radius,
                                         quiet.discretization_order);
        } catch (const std::invalid_argument&) {
          quiet_ok = false;
        }
        if (quiet_ok) {
          t.fail("noise_seed", t.value_text("noise_seed"),
                 message + " (after the noise; try another noise_seed)");
        }
        const std::string key =
            kind == Kind::regular_noisy ? "volume_fraction" : "anisotropy_factor";
        t.fail(key, t.value_text(key), message + kDoNotFit);
      }
      case Kind::regular:
        t.fail("volume_fraction", t.value_text("volume_fraction"), message + kDoNotFit);
      case Kind::regular_anisotropic:
        t.fail("anisotropy_factor", t.value_text("anisotropy_factor"), message + kDoNotFit);
    }
    throw ConfigError(message);
  }
}

// A regular placement whose lattice has a volume fraction more than kVolumeFractionTolerance
// (relative) away from the requested one: why (the anisotropy factors' product scales the box,
// eq. 4.52 with side n_a s f_a; the box is rounded to whole lattice spacings), or "".
std::string volume_fraction_warning(const TableReader& t, const MessSpec& s) {
  const auto* r = std::get_if<lattice::RegularPlacement>(&s.lattice.placement);
  if (r == nullptr) return {};
  const double requested = r->volume_fraction;
  const double actual = s.geometry.volume_fraction;
  if (!(std::abs(actual / requested - 1.0) > kVolumeFractionTolerance)) return {};
  const double product =
      r->anisotropic ? r->anisotropy_factor[0] * r->anisotropy_factor[1] * r->anisotropy_factor[2]
                     : 1.0;
  // Phi_actual = Phi / (product x rounding): what is left after the factors is the rounding.
  const double rounding = requested / (actual * product);
  std::string keys = t.path("volume_fraction") + " = " + t.value_text("volume_fraction");
  std::string why;
  if (std::abs(product - 1.0) > 1e-12) {
    keys += " with " + t.path("anisotropy_factor") + " = " + t.value_text("anisotropy_factor");
    why = fmt::format(
        "the box side along each axis is n_a s f_a, so the factors' product fx fy fz = {:.6g} "
        "divides the volume fraction (a single number f, sides 1/sqrt(f), 1/sqrt(f), f, keeps "
        "it); ",
        product);
  }
  why += fmt::format(
      "rounding the box to whole lattice spacings (l_e = {:.6g} m, {} x {} x {} nodes) changes "
      "the box volume by a factor {:.6g}",
      s.geometry.element_length, s.geometry.shape.nx(), s.geometry.shape.ny(),
      s.geometry.shape.nz(), rounding);
  return fmt::format(
      "{}: the lattice's actual volume fraction is {:.6g}, not {:.6g} ({:+.3g} %): {}", keys,
      actual, requested, 100.0 * (actual / requested - 1.0), why);
}

// R itself, before anything derived from it (l_e, the box, the volumes) can fail on another key.
double read_radius(const TableReader& t) {
  const double r = t.number_or("radius", 1.5e-6, Range::positive(), "m");
  if (!(r >= kMinRadius && r <= kMaxRadius)) {
    t.fail("radius", t.value_text("radius"),
           fmt::format("must be in [{:g}, {:g}] m: the lattice spacing l_e = 2R/(2 n_d + 1), the "
                       "particle volume 4/3 pi R^3 and the products of two dipole moments "
                       "(~ Ms^2 R^6) must stay normal doubles (the particles of an MRE are "
                       "of order 1e-6 m)",
                       kMinRadius, kMaxRadius));
  }
  return r;
}

void read_particles(const TableReader& root, MessSpec& s) {
  const TableReader t = root.table("particles");
  magnetism::MagneticParticles& p = s.particles;
  p.radius = read_radius(t);
  p.Ms = t.number_or("saturation_magnetization", 1.6e6, Range::positive(), "A/m");
  p.chi0 = t.number_or("susceptibility", 70.0, Range::positive(), "");
  s.demagnetization = t.boolean_or("demagnetization", false);
  s.self_energy = t.enumeration_or("self_energy", magnetism::SelfEnergyForm::consistent,
                                   {{"consistent", magnetism::SelfEnergyForm::consistent},
                                    {"linearized", magnetism::SelfEnergyForm::linearized}});
  s.lattice.iron_density =
      t.number_or("density", lattice::kIronDensity, Range::positive(), "kg/m^3");
  s.lattice.particle_radius = p.radius;
  read_placement(root, t, s);
  derive_checked(root, t, s);
  const std::string w = volume_fraction_warning(t, s);
  if (!w.empty()) s.warnings.push_back(w);
}

// ------------------------------------------------------------------------------------ [field]

void read_field(const TableReader& root, FieldSequence default_sequence, FieldSpec& f) {
  const TableReader t = root.table("field");
  const bool has_max = t.has("max");
  const bool has_steps = t.has("steps");
  const bool has_magnitudes = t.has("magnitudes");
  const bool has_values = t.has("values");
  // Read every key first, so that each is validated and known whatever the form.
  const auto max = t.optional_number("max", Range::positive(), "T");
  const long steps = t.integer_or("steps", 0, Range::between(1, 100000));
  const auto magnitudes = t.optional_number_list("magnitudes", Range::non_negative(), "T", 1);
  const auto values = t.optional_vector3_list("values", Range::any(), "T", 1);
  const auto theta = t.optional_number("theta", Range::between(0.0, 180.0), "deg");
  const auto phi = t.optional_number("phi", Range::between(-360.0, 360.0), "deg");
  const FieldSequence sequence = t.enumeration_or(
      "sequence", default_sequence, {{"loop", FieldSequence::loop}, {"up", FieldSequence::up}});

  std::vector<std::string> forms;
  if (has_max || has_steps) forms.emplace_back(has_max ? "max" : "steps");
  if (has_magnitudes) forms.emplace_back("magnitudes");
  if (has_values) forms.emplace_back("values");
  if (forms.empty()) {
    needed(t, "max",
           "give field.max and field.steps, field.magnitudes = [...] or field.values = "
           "[[Bx, By, Bz], ...] (T)");
  }
  if (forms.size() > 1) {
    t.fail(forms[1], t.value_text(forms[1]),
           fmt::format("give one of field.max and field.steps, field.magnitudes or "
                       "field.values (also given: field.{})",
                       forms[0]));
  }

  if (has_values) {
    if (theta) {
      t.fail("theta", t.value_text("theta"),
             "field.values gives whole vectors; the angles are only read with field.max or "
             "field.magnitudes");
    }
    if (phi) {
      t.fail("phi", t.value_text("phi"),
             "field.values gives whole vectors; the angles are only read with field.max or "
             "field.magnitudes");
    }
    if (t.has("sequence")) {
      t.fail("sequence", t.value_text("sequence"),
             "field.values is applied as given; sequence is only read with field.max or "
             "field.magnitudes");
    }
    f.form = FieldSpec::Form::vectors;
    f.values = to_vectors(*values);
    for (const auto& b : f.values) f.max = std::max(f.max, b.norm());
    return;
  }

  f.theta_deg = theta.value_or(0.0);
  f.phi_deg = phi.value_or(0.0);
  f.sequence = sequence;
  if (has_max || has_steps) {
    if (!has_steps) {
      needed(t, "steps",
             "field.max needs field.steps, the number of increments from 0 to max (integer >= 1)");
    }
    if (!has_max) needed(t, "max", "field.steps needs field.max (T)");
    f.form = FieldSpec::Form::max_and_steps;
    f.max = *max;
    f.steps = steps;
    f.magnitudes = config::evenly_spaced_from_zero(*max, steps);
  } else {
    f.form = FieldSpec::Form::magnitudes;
    f.magnitudes = *magnitudes;
    f.max = *std::max_element(f.magnitudes.begin(), f.magnitudes.end());
    if (f.sequence == FieldSequence::loop) {
      bool increasing = f.magnitudes.front() == 0.0;
      for (std::size_t i = 1; i < f.magnitudes.size(); ++i) {
        increasing = increasing && f.magnitudes[i] > f.magnitudes[i - 1];
      }
      if (!increasing || f.magnitudes.size() < 2) {
        t.fail("magnitudes", t.value_text("magnitudes"),
               "with field.sequence = \"loop\" the list must start at 0 and increase strictly "
               "(it is the rising branch 0 -> max of the loop)");
      }
    }
  }
  const std::vector<double> applied =
      f.sequence == FieldSequence::loop ? hysteresis_loop(f.magnitudes) : f.magnitudes;
  for (const double b : applied) f.values.push_back(field_vector(b, f.theta_deg, f.phi_deg));
}

// ----------------------------------------------------------------------------------- [solver]

constexpr double kMinMagnetizationAtol = 1e-15;  // Ms

// `loads_from_zero_load`: the run's protocol measures its load steps from the zero-load state
// (strain runs), the only ones whose start solver.load_step_start chooses.
void read_solver(const std::optional<TableReader>& solver, bool demagnetization,
                 bool loads_from_zero_load, SolverSpec& s) {
  s.magnetization.demagnetization = demagnetization;
  if (!solver) return;
  const TableReader& t = *solver;
  const std::string method =
      t.choice_or("method", "minimiser", {"minimiser", "lbfgs", "newton", "leapfrog"});
  s.method = method == "leapfrog" ? SolverMethod::leapfrog
             : method == "newton" ? SolverMethod::newton
             : method == "lbfgs"  ? SolverMethod::lbfgs
                                  : SolverMethod::minimiser;
  // The leapfrog reproduces the original code, which starts each strain and each field from the
  // previous one.
  const LoadStepStart start_default =
      s.method == SolverMethod::leapfrog ? LoadStepStart::previous : LoadStepStart::extrapolated;
  if (t.has("load_step_start") && !loads_from_zero_load) {
    t.fail("load_step_start", t.value_text("load_step_start"),
           "only read with run.type = \"mess_strain\" (the runs whose load steps start from the "
           "previous load value)");
  }
  s.load_step_start = t.enumeration_or("load_step_start", start_default,
                                       {{"extrapolated", LoadStepStart::extrapolated},
                                        {"secant", LoadStepStart::secant},
                                        {"previous", LoadStepStart::previous}});
  s.field_step_start = t.enumeration_or(
      "field_step_start",
      s.method == SolverMethod::leapfrog ? FieldStepStart::previous : FieldStepStart::extrapolated,
      {{"extrapolated", FieldStepStart::extrapolated}, {"previous", FieldStepStart::previous}});
  // Only the minimiser's multilevel preconditioner scales nodes by blocks, solves the gaps
  // between particles in contact and is kept between steps; the other methods would ignore
  // the choices.
  for (const char* key : {"node_scaling", "contact_gap", "preconditioner_reuse"}) {
    if (t.has(key) && s.method != SolverMethod::minimiser) {
      t.fail(key, t.value_text(key),
             fmt::format(R"(only read with solver.method = "minimiser" (the method is "{}"))",
                         method));
    }
  }
  s.node_scaling = t.enumeration_or(
      "node_scaling", mess::NodeScaling::blocks,
      {{"blocks", mess::NodeScaling::blocks}, {"diagonal", mess::NodeScaling::diagonal}});
  s.contact_gap =
      t.enumeration_or("contact_gap", mess::ContactGap::exact,
                       {{"exact", mess::ContactGap::exact}, {"none", mess::ContactGap::none}});
  s.preconditioner_reuse =
      t.number_or("preconditioner_reuse", s.preconditioner_reuse, Range::between(0.0, 10.0), "l_e");
  // [solver.minimiser] holds the criteria of lbfgs and newton alike.
  const std::string other = method == "leapfrog" ? "minimiser" : "leapfrog";
  if (t.has(other)) {
    t.fail(
        other, t.value_text(other),
        fmt::format(R"(only read with solver.method = "{}" (the method is "{}"))", other, method));
  }
  if (const auto m = t.optional_table("minimiser")) {
    s.minimiser.force_tolerance =
        m->number_or("force_tolerance", s.minimiser.force_tolerance, Range::positive(), "");
    s.minimiser.max_iterations =
        m->integer_or("max_iterations", s.minimiser.max_iterations, Range::between(1, 1e9));
  }
  if (const auto l = t.optional_table("leapfrog")) {
    s.leapfrog.dt = l->number_or("dt", s.leapfrog.dt, Range{0.0, 0.1, false, true}, "t_c");
    s.leapfrog.steps_per_round =
        l->integer_or("steps_per_round", s.leapfrog.steps_per_round, Range::between(1, 1e8));
    s.leapfrog.max_rounds =
        l->integer_or("max_rounds", s.leapfrog.max_rounds, Range::between(1, 1e6));
    s.leapfrog.drag = l->number_or("drag", s.leapfrog.drag, Range::positive(), "1/t_c");
  }
  if (const auto g = t.optional_table("magnetization")) {
    magnetism::MagnetizationOptions& o = s.magnetization;
    // A named tolerance first ("tight", the default, or the original code's loose band, only to
    // reproduce it: docs/magnetization-3d.md); atol and rtol written explicitly override it.
    using magnetism::MagnetizationTolerance;
    o.set_tolerance(g->enumeration_or("tolerance", MagnetizationTolerance::tight,
                                      {{"tight", MagnetizationTolerance::tight},
                                       {"original", MagnetizationTolerance::original}}));
    // Below ~1e-15 Ms the test asks for less than the residual's own rounding (about 2e-16 Ms
    // at |m| ~ 1), so every solve would be reported unconverged.
    o.atol = g->number_or("atol", o.atol, Range::at_least(kMinMagnetizationAtol), "Ms");
    o.rtol = g->number_or("rtol", o.rtol, Range::non_negative(), "");
    o.max_fixed_point_iterations = static_cast<int>(g->integer_or(
        "max_fixed_point_iterations", o.max_fixed_point_iterations, Range::between(1, 1e6)));
    o.max_anderson_iterations = static_cast<int>(g->integer_or(
        "max_anderson_iterations", o.max_anderson_iterations, Range::between(1, 1e6)));
    o.max_newton_iterations = static_cast<int>(
        g->integer_or("max_newton_iterations", o.max_newton_iterations, Range::between(1, 1e6)));
    o.check_stability = g->boolean_or("check_stability", o.check_stability);
  }
}

// ------------------------------------------------------------ scales that overflow (doubles)

// The solvers sum squares of forces over every coordinate (minimiser norms, the leapfrog's
// scaled accelerations) and products of energies; a force scale F is safe while
// F^2 x 3 N x kHeadroom is a finite double (kHeadroom leaves room for strains, field and
// particle-count factors far beyond any real run). Past it the relaxation produces inf/NaN;
// such parameters are refused here instead.
constexpr double kHeadroom = 1e10;
// The largest chi0 H/Ms of the applied field with the consistent self energy (check_load_scales).
constexpr double kMaxSaturation = 1e12;
// Fields up to this (T) are lab fields: past kMaxSaturation with one, chi0 is blamed instead.
constexpr double kLabField = 1e3;

// The largest force scale whose squares summed over `coordinates` stay finite (header above).
double largest_scale(double coordinates) {
  return std::sqrt(std::numeric_limits<double>::max() / (coordinates * kHeadroom));
}

// Refuses `key` of `table` (its value as written, or `fallback` when it is the default).
[[noreturn]] void refuse(const TableReader& root, const char* table, const char* key,
                         const std::string& fallback, const std::string& why) {
  const auto t = root.optional_table(table);
  if (!t) throw ConfigError(fmt::format("{}.{} = {}: {}", table, key, fallback, why));
  t->fail(key, text_or(*t, key, fallback), why);
}

// The key of a [field] or [stress] table that holds the largest value (max, magnitudes or
// values), refused with `why`.
[[noreturn]] void refuse_load(const TableReader& t, const std::string& why) {
  for (const char* key : {"max", "magnitudes", "values"}) {
    if (t.has(key)) t.fail(key, t.value_text(key), why);
  }
  throw ConfigError(fmt::format("[{}]: {}", t.path(), why));
}

// The applied field's scales (top: the largest safe force scale, elastic: k_eff l_e): the
// Froehlich-Kennelly argument chi0 H/Ms (eq. 4.55), and the Zeeman energy of a saturated
// particle Ms V_p B (eq. 4.72) over R and over the elastic energy scale k_eff l_e^2 (the
// leapfrog's units). The applied stress: the traction force on a face node ~ sigma l_e^2.
void check_load_scales(const TableReader& root, const MessSpec& s, double top, double elastic) {
  const double ms = s.particles.Ms;
  const double r = s.particles.radius;
  const double l_e = s.geometry.element_length;
  const double zeeman_per_tesla = ms * lattice::sphere_volume(r);
  const double overflow = std::min({top * kMu0 * ms / s.particles.chi0, top * r / zeeman_per_tesla,
                                    top * elastic * l_e / zeeman_per_tesla});
  // Eq. 4.76 has log(1 - |M|/Ms), and 1 - |M|/Ms = 1/(1 + chi0 H/Ms) (eq. 4.55): past
  // chi0 H/Ms = kMaxSaturation doubles no longer resolve it (the self energy becomes NaN).
  const double saturation = kMaxSaturation * kMu0 * ms / s.particles.chi0;
  // (E_self of eq. 4.76 is recorded whichever particles.self_energy the solver uses.)
  const double b_limit = std::min(overflow, saturation);
  if (!(s.field.max <= b_limit) && b_limit == saturation && s.field.max <= kLabField) {
    // A lab field: the material's chi0 is what is out of range.
    refuse(root, "particles", "susceptibility", "70 (default)",
           fmt::format("with the largest field {:g} T, chi0 H/Ms reaches {:.3g}, above {:g}, "
                       "where 1 - |M|/Ms in the self energy's log(1 - |M|/Ms) (eq. 4.76) is "
                       "below what doubles resolve; chi0 must be <= {:.3g} here (iron's is of "
                       "order 1e2-1e3)",
                       s.field.max, s.particles.chi0 * s.field.max / (kMu0 * ms), kMaxSaturation,
                       kMaxSaturation * kMu0 * ms / s.field.max));
  }
  if (!(s.field.max <= b_limit)) {
    const std::string why =
        b_limit == overflow
            ? fmt::format(
                  "the Froehlich-Kennelly argument chi0 H/Ms or the Zeeman energy Ms V_p "
                  "B = {:.3g} J of a particle is too large for the solvers' sums over the "
                  "{} nodes to stay finite doubles",
                  zeeman_per_tesla * s.field.max, s.geometry.node_count())
            : fmt::format(
                  "chi0 H/Ms exceeds {:g}, where 1 - |M|/Ms in the self energy's "
                  "log(1 - |M|/Ms) (eq. 4.76) is below what doubles resolve",
                  kMaxSaturation);
    refuse_load(root.table("field"),
                fmt::format("the largest field must be <= {:.3g} T (mu0 H): beyond it {} (lab "
                            "fields are below 100 T)",
                            b_limit, why));
  }
  s.protocol->check_scales(root, s, top, elastic);  // the load's own scales (mess_stress)
}

// Elastic force scale k_eff l_e (the seed's characteristic spring force, docs/lattice.md) and
// magnetic mu0 Ms^2 R^2 (the force between two saturated particles at contact, eq. 4.71 over R;
// energy scale mu0 Ms^2 R^3).
void check_scales(const TableReader& root, const MessSpec& s) {
  const lattice::LatticeSpec& l = s.lattice;
  const double l_e = s.geometry.element_length;
  const double coordinates = 3.0 * static_cast<double>(s.geometry.node_count());
  const double top = largest_scale(coordinates);
  const lattice::LatticeStiffness k = lattice::polymer_stiffness(
      l.shear_modulus_rule, l.youngs_modulus, l.poisson_ratio, l_e, l.stiffness_ratio);
  const double k_eff = lattice::effective_spring_constant(k.springs);
  const double elastic = k_eff * l_e;
  const double smallest = std::sqrt(std::numeric_limits<double>::min() * kHeadroom);
  if (!(elastic <= top && elastic >= smallest) || !std::isfinite(k.kappa * l_e * l_e * l_e)) {
    refuse(
        root, "model", "youngs_modulus", "9000 (default)",
        fmt::format("gives the force scale k_eff l_e = {:.3g} N (elastic energy scale k_e "
                    "l_e^2 = {:.3g} J) outside [{:.3g}, {:.3g}] N, where the solvers' sums of "
                    "squares over the {} nodes stay finite doubles; use a physical modulus "
                    "(the polymer's is of order 1e4 Pa)",
                    elastic, k.springs.edge * l_e * l_e, smallest, top, s.geometry.node_count()));
  }
  if (s.geometry.particle_count() > 0) {
    const double ms = s.particles.Ms;
    const double r = s.particles.radius;
    const double magnetic = kMu0 * ms * ms * r * r;
    // Also in the leapfrog's units of k_eff l_e (the scaled accelerations).
    if (!(magnetic <= top) || !(magnetic / elastic <= top)) {
      refuse(
          root, "particles", "saturation_magnetization", "1.6e6 (default)",
          fmt::format("gives the magnetic force scale mu0 Ms^2 R^2 = {:.3g} N (energy scale "
                      "mu0 Ms^2 R^3 = {:.3g} J), above {:.3g} N (or {:.3g} k_eff l_e), where the "
                      "solvers' sums of squares stay finite doubles; iron's Ms is 1.6e6 A/m",
                      magnetic, magnetic * r, top, top));
    }
  }
  check_load_scales(root, s, top, elastic);
}

// The leapfrog is unstable for dt >= 2/omega_max of the lattice (docs/mess-solvers.md);
// omega_max is known for the seed profile at n_d = 2..5 (leapfrog_stability_limit).
void check_leapfrog(const std::optional<TableReader>& solver, const MessSpec& s) {
  if (s.solver.method != SolverMethod::leapfrog || !s.profile->leapfrog_stability_tabulated) {
    return;
  }
  const auto limit = leapfrog_stability_limit(s.lattice.discretization_order);
  if (!limit || s.solver.leapfrog.dt < *limit) return;
  const auto leapfrog = solver->optional_table("leapfrog");
  const std::string text =
      leapfrog && leapfrog->has("dt") ? leapfrog->value_text("dt") : "0.005 (default)";
  const std::string key = leapfrog ? leapfrog->path("dt") : solver->path("leapfrog.dt");
  throw ConfigError(fmt::format(
      "{} = {}: must be < {:.2g} (t_c) with profile = \"{}\" and discretization_order = {}: "
      "the damped leapfrog is unstable above 2/omega_max of this lattice and its results "
      "become non-finite",
      key, text, *limit, s.profile->name, s.lattice.discretization_order));
}

}  // namespace

// ------------------------------------------------------------------------------------ public

std::optional<double> leapfrog_stability_limit(int discretization_order) {
  // Measured by power iteration on the seed lattice's force Jacobian (docs/mess-solvers.md).
  switch (discretization_order) {
    case 2:
      return 4.8e-3;
    case 3:
      return 5.6e-3;
    case 4:
      return 5.7e-3;
    case 5:
      return 5.8e-3;
    default:
      return std::nullopt;
  }
}

std::vector<std::string> mess_run_type_names() { return mess_protocol::protocol_names(); }

std::string to_string(LoadKind kind) {
  switch (kind) {
    case LoadKind::shear:
      return "shear";
    case LoadKind::tension:
      return "tension";
    case LoadKind::compression:
      return "compression";
    case LoadKind::torsion:
      return "torsion";
  }
  return {};
}

std::vector<double> hysteresis_loop(const std::vector<double>& up) {
  std::vector<double> out(up.begin(), up.end());
  if (up.size() < 2) return out;
  const auto n = up.size();
  for (std::size_t i = n - 1; i-- > 0;) out.push_back(up[i]);   // max -> 0, without max
  for (std::size_t i = 1; i < n; ++i) out.push_back(-up[i]);    // 0 -> -max, without 0
  for (std::size_t i = n - 1; i-- > 0;) out.push_back(-up[i]);  // -max -> 0, without -max
  for (std::size_t i = 1; i < n; ++i) out.push_back(up[i]);     // 0 -> max, without 0
  return out;
}

namespace {
// cos and sin of an angle in degrees, exact (0, +-1) at multiples of 90 degrees, so that a field
// along an axis has no 6e-17 components along the others.
double cos_deg(double deg) {
  const double quarter = deg / 90.0;
  if (quarter == std::round(quarter)) {
    const auto q = static_cast<long>(std::round(quarter)) % 4;
    return q == 0 ? 1.0 : (q == 2 || q == -2) ? -1.0 : 0.0;
  }
  return std::cos(deg * kDegree);
}
double sin_deg(double deg) { return cos_deg(90.0 - deg); }
}  // namespace

Eigen::Vector3d field_vector(double magnitude, double theta_deg, double phi_deg) {
  if (magnitude == 0.0) return Eigen::Vector3d::Zero();  // no -0 from the loop's -u
  const double st = sin_deg(theta_deg);
  return magnitude *
         Eigen::Vector3d(st * cos_deg(phi_deg), st * sin_deg(phi_deg), cos_deg(theta_deg));
}

std::size_t MessSpec::load_step_count() const { return protocol->load_values().size(); }

std::size_t MessSpec::relaxation_count() const { return field.values.size() * load_step_count(); }

bool MessSpec::keeps_earlier_load_results() const {
  return solver.load_step_start != LoadStepStart::previous && load_step_count() > 1 &&
         protocol->loads_from_zero_load_state();
}

bool MessSpec::keeps_earlier_field_result() const {
  return solver.field_step_start == FieldStepStart::extrapolated && load_step_count() <= 1;
}

MessSpec read_mess_spec(const TableReader& root, std::string_view run_type) {
  // std::invalid_argument for a name that is not a registered protocol (a programming error).
  const mess_protocol::ProtocolType& type = mess_protocol::find_protocol(run_type);
  MessSpec s;
  s.run_type = type.name;
  if (const auto run = root.optional_table("run")) s.title = run->string_or("title", "");
  read_model(root.optional_table("model"), s);
  read_particles(root, s);
  s.analysis = read_analysis(root.optional_table("analysis"), s.particles.radius);
  read_field(root, type.default_field_sequence, s.field);
  // The protocol's own table(s), e.g. [strain] (protocols/*_protocol.cpp).
  s.protocol = mess_protocol::read_protocol(root, run_type);
  // The optional energy terms' tables [terms.<name>] (terms/energy_term.hpp).
  s.terms = mess::read_term_tables(root);

  read_solver(root.optional_table("solver"), s.demagnetization,
              s.protocol->loads_from_zero_load_state(), s.solver);
  check_scales(root, s);
  check_leapfrog(root.optional_table("solver"), s);
  if (const auto t = root.optional_table("output")) {
    s.output.node_positions = t->boolean_or("node_positions", false);
    s.output.checkpoint_every = t->integer_or("checkpoint_every", 1, Range::between(0, 1e9));
    s.output.keep_final_state = t->boolean_or("keep_final_state", true);
  }
  return s;
}

MessSpec read_mess_run_file(const TableReader& root) {
  const TableReader run = root.table("run");
  const std::string type = run.choice("type", mess_run_type_names());
  (void)run.integer_or("threads", 0, Range::non_negative());
  MessSpec spec = read_mess_spec(root, type);
  root.reject_unknown_keys();
  return spec;
}

}  // namespace mresim::mess_config
