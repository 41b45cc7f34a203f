// Zeeman energy in a uniform field gradient: an optional energy term, present when the run
// file has a [terms.field_gradient] table (docs/run-files-3d.md#terms-field-gradient).
//
// The applied field is H(r) = H_ext + G (r - r_0): H_ext the [field] value, G the constant
// gradient tensor G_ab = dH_a/dx_b (A/m^2), r_0 the point where the field is H_ext. Eq. 4.70
// with this field splits into the uniform Zeeman term (terms/magnetic_terms.cpp) plus
//
//   E = -mu0 V sum_i M_i . G (c_i - r_0),      dE/dc_i = -mu0 V G^T M_i,
//
// so the force on particle i is mu0 V G M_i = mu0 (m_i . grad) H, the Kelvin force of
// eq. 4.77 (G^T = G below). At fixed M the energy is linear in the centres: its Hessian is
// exactly zero, and it does not depend on the node positions.
//
// G must be symmetric (a curl-free field in a current-free region: dH_a/dx_b = dH_b/dx_a) and
// traceless (div B = mu0 div H = 0 with no magnetic material outside the particles); the reader
// refuses any other G, since only then is E the potential of the Kelvin force.
//
// Approximation: the particles' magnetizations are solved in the uniform field H_ext only
// (magnetization/self_consistent.hpp does not see G), so the term is valid while the field
// changes little over the sample, |G| L << |H_ext| (L the box size). It adds the force of the
// gradient on the magnetization the uniform field induces; it does not change that
// magnetization.

#include <Eigen/Core>
#include <algorithm>
#include <any>
#include <cmath>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <utility>

#include "mresim/config/table_reader.hpp"
#include "mresim/core/constants.hpp"
#include "mresim/mess/terms/energy_term.hpp"

namespace mresim::mess {
namespace {

struct FieldGradient {
  Eigen::Matrix3d gradient = Eigen::Matrix3d::Zero();  // G_ab = dH_a/dx_b, A/m^2
  std::optional<Eigen::Vector3d> origin;  // r_0, m; empty: the centre of the lattice's box
};

std::string text_of(double v) {
  std::ostringstream out;
  out << v;
  return out.str();
}

// Symmetric and traceless to rounding of the numbers as written (1e-9 of the largest entry).
void check_gradient(const config::TableReader& t, const Eigen::Matrix3d& g) {
  const double scale = g.cwiseAbs().maxCoeff();
  const double tolerance = 1e-9 * scale;
  const char* axes = "xyz";
  for (int a = 0; a < 3; ++a) {
    for (int b = a + 1; b < 3; ++b) {
      if (std::abs(g(a, b) - g(b, a)) <= tolerance) continue;
      t.fail("gradient", t.value_text("gradient"),
             std::string("must be symmetric (a curl-free field has dH_") + axes[a] + "/d" +
                 axes[b] + " = dH_" + axes[b] + "/d" + axes[a] + "), here " + text_of(g(a, b)) +
                 " and " + text_of(g(b, a)) + " A/m^2");
    }
  }
  if (std::abs(g.trace()) > tolerance) {
    t.fail("gradient", t.value_text("gradient"),
           "must be traceless (div B = 0: dH_x/dx + dH_y/dy + dH_z/dz = 0), here the sum is " +
               text_of(g.trace()) + " A/m^2");
  }
}

// [terms.field_gradient]: gradient = 9 numbers, row a = component H_a, column b = d/dx_b
// (row-major, A/m^2); origin = [x, y, z] (m, optional).
std::any read_field_gradient(const config::TableReader& t) {
  const std::vector<double> g = t.number_list("gradient", config::Range::any(), "A/m^2", 9);
  if (g.size() != 9) {
    t.fail("gradient", t.value_text("gradient"),
           "expected 9 numbers [dHx/dx, dHx/dy, dHx/dz, dHy/dx, ..., dHz/dz] (A/m^2)");
  }
  FieldGradient p;
  for (std::size_t k = 0; k < 9; ++k) {
    p.gradient(static_cast<Eigen::Index>(k / 3), static_cast<Eigen::Index>(k % 3)) = g[k];
  }
  check_gradient(t, p.gradient);
  if (const auto o = t.optional_number_list("origin", config::Range::any(), "m", 3)) {
    if (o->size() != 3) t.fail("origin", t.value_text("origin"), "expected [x, y, z] (m)");
    p.origin = Eigen::Vector3d((*o)[0], (*o)[1], (*o)[2]);
  }
  t.reject_unknown_keys();
  return p;
}

class FieldGradientTerm final : public EnergyTerm {
 public:
  // Fixed-size Eigen values (no alignment requirement): copied in.
  FieldGradientTerm(Eigen::Matrix3d gradient, Eigen::Vector3d origin)
      : gradient_(std::move(gradient)), origin_(std::move(origin)) {}

  std::string_view name() const override { return "field_gradient"; }
  std::string_view equation() const override { return "eqs. 4.70, 4.77"; }
  std::string_view title() const override { return "field gradient"; }

  TermValue evaluate(const TermState& s, TermGradient* gradient) const override {
    const double scale = -kMu0 * s.model.particles.volume();
    double sum = 0.0;
    for (Eigen::Index i = 0; i < s.centres.cols(); ++i) {
      sum += s.magnetizations.col(i).dot(gradient_ * (s.centres.col(i) - origin_));
      if (gradient != nullptr) {
        gradient->centres.col(i) += scale * (gradient_.transpose() * s.magnetizations.col(i));
      }
    }
    return {scale * sum, 0.0};
  }

  HessianKind hessian_kind() const override { return HessianKind::zero; }
  void add_hessian_product(const TermState& /*state*/, const TermGradient& /*v*/,
                           TermGradient& /*out*/) const override {}

 private:
  Eigen::Matrix3d gradient_;
  Eigen::Vector3d origin_;
};

std::unique_ptr<EnergyTerm> make_field_gradient(const TermContext& context, const std::any& p) {
  const auto& parameters = std::any_cast<const FieldGradient&>(p);
  const Eigen::Matrix3Xd& x = context.lattice.positions;
  const Eigen::Vector3d centre =
      x.cols() > 0 ? Eigen::Vector3d(0.5 * (x.rowwise().minCoeff() + x.rowwise().maxCoeff()))
                   : Eigen::Vector3d::Zero();
  return std::make_unique<FieldGradientTerm>(parameters.gradient,
                                             parameters.origin.value_or(centre));
}

const EnergyTermRegistrar field_gradient_term_registrar(
    {.name = "field_gradient",
     .order = 35,  // after the uniform Zeeman term (30)
     .always_present = false,
     .read = read_field_gradient,
     .make = make_field_gradient});

}  // namespace
}  // namespace mresim::mess
