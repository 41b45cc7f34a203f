// mess_stress (Sections 4.2.7-4.2.8): at every field, a series of applied stresses (shear,
// tension or compression tractions on one face or both; the [stress] table,
// docs/run-files-3d.md). The strain each stress reaches is measured on the faces relative to
// the zero-stress result at that field, and the modulus of each field is the slope of stress
// over strain through 0.

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <string>

#include "mresim/config/config_error.hpp"
#include "mresim/mess/protocols/load_tables.hpp"
#include "mresim/mess/protocols/loading.hpp"
#include "mresim/mess/protocols/protocol.hpp"

namespace mresim::mess_protocol {
namespace {

using config::ConfigError;
using config::Range;
using config::TableReader;
using load_tables::LoadAxes;
using load_tables::parse_kind;
using load_tables::read_axes;
using load_tables::read_load_values;
using mess_config::LoadKind;
using mess_config::StressLoading;
using mess_config::StressSpec;

// The largest |stress| in units of model.youngs_modulus (check_scales).
constexpr double kMaxStressOverModulus = 10.0;

// Moved unchanged from run_file/read_mess_spec.cpp.
StressSpec read_stress(const TableReader& root) {
  const TableReader t = root.table("stress");
  StressSpec s;
  s.kind = parse_kind(t.choice("kind", {"shear", "tension", "compression"}));
  const LoadAxes axes = read_axes(t, s.kind);
  s.normal = axes.normal;
  s.direction = axes.direction;
  s.loading = t.choice_or("loading", "one_face", {"one_face", "both_faces"}) == "one_face"
                  ? StressLoading::one_face
                  : StressLoading::both_faces;
  const Range values = s.kind == LoadKind::shear ? Range::any() : Range::non_negative();
  s.values = read_load_values(t, Range::positive(), values, "Pa", "stress");
  if (s.kind == LoadKind::compression) {
    for (double& v : s.values) v = 0.0 - v;  // +0, not -0
  }
  return s;
}

// The key of the [stress] table that holds the largest value (max or values), refused with `why`
// (as run_file/read_mess_spec.cpp refuses the [field] table's).
[[noreturn]] void refuse_load(const TableReader& t, const std::string& why) {
  for (const char* key : {"max", "magnitudes", "values"}) {
    if (t.has(key)) t.fail(key, t.value_text(key), why);
  }
  throw ConfigError(fmt::format("[{}]: {}", t.path(), why));
}

class Stress final : public ProtocolWith<StressSpec> {
 public:
  using ProtocolWith::ProtocolWith;

  [[nodiscard]] std::vector<double> load_values() const override { return settings().values; }
  [[nodiscard]] bool has_load() const override { return true; }
  [[nodiscard]] const char* load_unit() const override { return "Pa"; }

  // Stresses act on the initial lattice's faces (loading.hpp, stress_load).
  [[nodiscard]] LoadState load(const lattice::Lattice& lattice, const StepSpec& step,
                               const Eigen::Matrix3Xd& reference) const override {
    return stress_load(lattice, settings(), step.load_value, reference);
  }

  [[nodiscard]] double measured_strain(const lattice::Lattice& lattice, const StepSpec& /*step*/,
                                       const Eigen::Matrix3Xd& positions,
                                       const Eigen::Matrix3Xd& zero_load) const override {
    return mess_protocol::measured_strain(lattice, settings(), positions, zero_load);
  }

  [[nodiscard]] Analysis analysis() const override {
    Analysis a;
    a.kind = AnalysisKind::stress_modulus;
    a.modulus_name = settings().kind == LoadKind::shear ? "G_eff" : "E_eff";
    return a;
  }

  // The applied stress: the traction force on a face node ~ sigma l_e^2 (moved unchanged from
  // run_file/read_mess_spec.cpp, check_load_scales).
  void check_scales(const TableReader& root, const mess_config::MessSpec& s, double top,
                    double elastic) const override {
    const double l_e = s.geometry.element_length;
    double sigma = 0.0;
    for (const double v : settings().values) sigma = std::max(sigma, std::abs(v));
    const double overflow_limit = std::min(top / (l_e * l_e), top * elastic / (l_e * l_e));
    const double strain_limit = kMaxStressOverModulus * s.lattice.youngs_modulus;
    if (!(sigma <= overflow_limit)) {
      refuse_load(
          root.table("stress"),
          fmt::format("the largest stress must be <= {:.3g} Pa: beyond it the traction "
                      "force on a face node (~ stress x l_e^2, l_e = {:.3g} m) is too "
                      "large for the solvers' sums over the {} nodes to stay finite "
                      "doubles (the polymer's modulus is of order 1e4 Pa)",
                      std::min(overflow_limit, strain_limit), l_e, s.geometry.node_count()));
    }
    if (!(sigma <= strain_limit)) {
      refuse_load(root.table("stress"),
                  fmt::format("the largest stress must be <= {:g} x model.youngs_modulus = "
                              "{:.6g} Pa: beyond it the engineering strain (~ stress/E) exceeds "
                              "{:g}, far outside the lattice's small-strain springs, and the "
                              "relaxation does not converge",
                              kMaxStressOverModulus, strain_limit, kMaxStressOverModulus));
    }
  }

  void describe(const mess_config::MessSpec& s, app::InfoReport& r) const override {
    const StressSpec& st = settings();
    const std::string sec = "stress";
    load_tables::describe_axes(st, sec, r);
    r.add_text(sec, "loading", st.loading == StressLoading::one_face ? "one_face" : "both_faces",
               st.loading == StressLoading::one_face
                   ? "lower face fixed, traction on the upper face"
                   : "opposite tractions on both faces, nothing fixed");
    const auto [lo, hi] = std::minmax_element(st.values.begin(), st.values.end());
    r.add(sec, "min", *lo, "Pa", st.kind == LoadKind::compression ? "compression is negative" : "");
    r.add(sec, "max", *hi, "Pa");
    const Eigen::Vector3d& L = s.geometry.box_lengths;
    const int a = (st.normal + 1) % 3;
    const int b = (st.normal + 2) % 3;
    r.add(sec, "loaded_face_area", L[a] * L[b], "m^2", "initial area of the loaded face");
    r.add_integer(sec, "values", static_cast<std::int64_t>(st.values.size()), "",
                  "including the zero-stress reference");
  }
};

const ProtocolRegistrar stress_protocol_registrar(
    {"mess_stress",
     "3D lattice (MESS): applied shear, tension or compression stress",
     {"stress"},
     [](const TableReader& root) { return std::make_shared<const Stress>(read_stress(root)); },
     mess_config::FieldSequence::up,
     4});

}  // namespace
}  // namespace mresim::mess_protocol
