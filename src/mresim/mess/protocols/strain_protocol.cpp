// mess_strain (Sections 4.2.7-4.2.8): at every field, a series of applied strains (shear,
// tension, compression or torsion; the [strain] table, docs/run-files-3d.md) measured from the
// converged zero-strain state at that field; the modulus of each field is fitted to the energy
// density (G_eff, E_eff or a torsion stiffness, eq. 4.97).

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <numbers>

#include "mresim/mess/protocols/load_tables.hpp"
#include "mresim/mess/protocols/loading.hpp"
#include "mresim/mess/protocols/protocol.hpp"

namespace mresim::mess_protocol {
namespace {

using config::Range;
using config::TableReader;
using load_tables::LoadAxes;
using load_tables::parse_kind;
using load_tables::read_axes;
using load_tables::read_load_values;
using mess_config::LoadKind;
using mess_config::ShearBoundary;
using mess_config::StrainSpec;

constexpr double kDegree = std::numbers::pi / 180.0;
constexpr double kRadian = 180.0 / std::numbers::pi;

// Moved unchanged from run_file/read_mess_spec.cpp.
StrainSpec read_strain(const TableReader& root) {
  const TableReader t = root.table("strain");
  StrainSpec s;
  s.kind = parse_kind(t.choice("kind", {"shear", "tension", "compression", "torsion"}));
  const LoadAxes axes = read_axes(t, s.kind);
  s.normal = axes.normal;
  s.direction = axes.direction;
  if (s.kind == LoadKind::shear) {
    s.boundary = t.choice_or("boundary", "all_faces", {"all_faces", "normal_faces"}) == "all_faces"
                     ? ShearBoundary::all_faces
                     : ShearBoundary::normal_faces;
  } else if (t.has("boundary")) {
    t.fail("boundary", t.value_text("boundary"), "only read with strain.kind = \"shear\"");
  }
  switch (s.kind) {
    case LoadKind::shear:
      s.values =
          read_load_values(t, Range::open(0.0, 1.0), Range::open(-1.0, 1.0), "rad", "strain");
      break;
    case LoadKind::tension:
    case LoadKind::compression:
      // Magnitudes: compression is stored negative below.
      s.values =
          read_load_values(t, Range::open(0.0, 1.0), Range{0.0, 1.0, true, false}, "", "strain");
      if (s.kind == LoadKind::compression) {
        for (double& v : s.values) v = 0.0 - v;  // +0, not -0
      }
      break;
    case LoadKind::torsion:
      s.values = read_load_values(t, Range{0.0, 180.0, false, true}, Range::between(-180.0, 180.0),
                                  "deg", "strain");
      for (double& v : s.values) v *= kDegree;
      break;
  }
  return s;
}

class Strain final : public ProtocolWith<StrainSpec> {
 public:
  using ProtocolWith::ProtocolWith;

  [[nodiscard]] std::vector<double> load_values() const override { return settings().values; }
  [[nodiscard]] bool has_load() const override { return true; }
  [[nodiscard]] const char* load_unit() const override {
    const LoadKind k = settings().kind;
    return k == LoadKind::shear || k == LoadKind::torsion ? "rad" : "1";
  }

  // Strain values are applied relative to the zero-strain result at the same field.
  [[nodiscard]] bool loads_from_zero_load_state() const override { return true; }
  [[nodiscard]] LoadState load(const lattice::Lattice& lattice, const StepSpec& step,
                               const Eigen::Matrix3Xd& reference) const override {
    return strain_load(lattice, settings(), step.load_value, reference);
  }

  // The strain axis of the modulus fit: tan(gamma) for shear (the engineering shear strain of
  // the affine field u = h tan(gamma), for which linear elasticity gives the energy density
  // G tan^2(gamma)/2), the engineering strain, the twist angle.
  [[nodiscard]] double measured_strain(const lattice::Lattice& /*lattice*/, const StepSpec& step,
                                       const Eigen::Matrix3Xd& /*positions*/,
                                       const Eigen::Matrix3Xd& /*zero_load*/) const override {
    return settings().kind == LoadKind::shear ? std::tan(step.load_value) : step.load_value;
  }

  [[nodiscard]] Analysis analysis() const override {
    const LoadKind kind = settings().kind;
    Analysis a;
    a.kind = AnalysisKind::energy_modulus;
    a.modulus_name = kind == LoadKind::shear     ? "G_eff"
                     : kind == LoadKind::torsion ? "torsion_stiffness"
                                                 : "E_eff";
    // The original's zero-point rule is for shear (modulus_fit.hpp).
    a.drop_zero_point_above_next = kind == LoadKind::shear;
    return a;
  }

  void describe(const mess_config::MessSpec& /*spec*/, app::InfoReport& r) const override {
    const StrainSpec& st = settings();
    const std::string sec = "strain";
    load_tables::describe_axes(st, sec, r);
    if (st.kind == LoadKind::shear) {
      r.add_text(sec, "boundary",
                 st.boundary == ShearBoundary::all_faces ? "all_faces" : "normal_faces",
                 st.boundary == ShearBoundary::all_faces
                     ? "every surface node follows u = h tan(gamma) (eq. 4.96)"
                     : "faces normal to the normal axis held, side faces free");
    }
    const auto [lo, hi] = std::minmax_element(st.values.begin(), st.values.end());
    const bool angle = st.kind == LoadKind::torsion;
    const double scale = angle ? kRadian : 1.0;
    const std::string unit = st.kind == LoadKind::shear ? "rad" : angle ? "deg" : "";
    r.add(sec, "min", *lo * scale, unit,
          st.kind == LoadKind::compression ? "compression is negative" : "");
    r.add(sec, "max", *hi * scale, unit);
    r.add_integer(sec, "values", static_cast<std::int64_t>(st.values.size()), "",
                  "including the zero-strain reference");
  }
};

const ProtocolRegistrar strain_protocol_registrar(
    {"mess_strain",
     "3D lattice (MESS): shear, tension, compression or torsion; G_eff / E_eff",
     {"strain"},
     [](const TableReader& root) { return std::make_shared<const Strain>(read_strain(root)); },
     mess_config::FieldSequence::up,
     2});

}  // namespace
}  // namespace mresim::mess_protocol
