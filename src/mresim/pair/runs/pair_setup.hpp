#pragma once

#include <optional>
#include <string>
#include <vector>

#include "mresim/config/table_reader.hpp"
#include "mresim/pair/hysteresis.hpp"

// Reading the two-dipole tables of a run file: [material], [springs], [penalty], [field],
// [critical_fields] (documented key by key in docs/run-files.md).
namespace mresim::pair::runs {

// Where the spring constants come from. Puljiz constants depend on S0, so they are resolved
// only when the pair is built (a map over S0 recomputes them at every point).
struct StiffnessSource {
  enum class Kind { spring_constant, three_spring_constants, shear_modulus, youngs_modulus };
  Kind kind = Kind::spring_constant;
  double k = 4e-2;                 // N/m  (single spring: k; three springs: unused)
  double k0 = 0.0;                 // N/m
  double k12 = 0.0;                // N/m
  double modulus = 0.0;            // Pa, G or E
  bool chapter3_cylinder = false;  // youngs_modulus: k = E pi D^2/(2 S0) instead of E pi R^2/S0

  std::string describe() const;
};

// Everything one two-dipole loop needs, before the stiffness is resolved.
struct PairSetup {
  std::string label;
  SphereMaterial material;
  SpringModel model = SpringModel::single;
  StiffnessSource stiffness;
  double rest_separation = 9e-6;
  OverlapPenalty penalty = OverlapPenalty::tanh_default(1.5e-6);
  SweepOptions sweep;
  double critical_field_tolerance = 1e-4;

  // The pair with its spring constants resolved at the current S0.
  PairSystem system() const;
  PairSystem system_at(double s0) const;
};

// Reads the setup from `scope` (the root, or one [[case]] table), every key falling back to
// `base`. At the root, [springs] is required; in a case every table is optional.
// `stiffness_required` is false for maps whose rows set k themselves.
PairSetup read_pair_setup(const config::TableReader& scope, const PairSetup& base, bool is_root,
                          bool stiffness_required = true);

// The root setup plus one setup per [[case]] (label required there); if there are no cases,
// the root setup alone, labelled with [run].title.
std::vector<PairSetup> read_pair_cases(const config::TableReader& root);

// Checks a separation S0 > 2R for a value coming from elsewhere (map axes, ensembles).
void require_separable(const config::TableReader& table, const std::string& key, double s0,
                       const SphereMaterial& material);

// Checks the separations of a map or ensemble axis ("separation" -> separation_min/_max or
// separation_values): every one > 2R and <= 1e100 R (the solver squares lengths in units of R).
void require_separations(const config::TableReader& table, const std::string& axis,
                         const std::vector<double>& separations, const SphereMaterial& material);

// Validation of the assembled pair (S0 > 2R, WCA r_cut > r_min, ...), naming the key at fault,
// including the scales of the solver's units: R^3, mu0 Ms^2 V, the reduced field, spring and
// penalty constants must be finite normal doubles (otherwise the results would be NaN).
void validate_pair(const config::TableReader& scope, const PairSetup& setup);

}  // namespace mresim::pair::runs
