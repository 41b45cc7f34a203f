// The magnetic terms of the 3D model as EnergyTerms (always present; zero without particles),
// wrapping the kernels of terms/magnetic_energy.hpp: Zeeman (eq. 4.70), dipole-dipole (eq.
// 4.71, gradient eq. 4.78), the self-energy (eq. 4.76, in the total) and its linearized form
// (eq. 4.73, reported only). WCA is in wca_term.cpp. Their energies are exactly those of
// magnetism::magnetic_energies(); their gradients are with respect to the centres at fixed M.
//
// Hessians at fixed M: Zeeman and self-energy do not depend on the centres (uniform field),
// so theirs vanish; the dipole term uses the central-difference default of EnergyTerm (its
// exact pair Hessian, a rank-4 tensor contraction, is not worth it for N_p^2 pairs).

#include "mresim/mess/terms/energy_term.hpp"

namespace mresim::mess {
namespace {

namespace mm = mresim::magnetism;

// A magnetic term without a dependence on the centres at fixed M.
class CentreFreeTerm : public EnergyTerm {
 public:
  HessianKind hessian_kind() const override { return HessianKind::zero; }
  void add_hessian_product(const TermState& /*state*/, const TermGradient& /*v*/,
                           TermGradient& /*out*/) const override {}
};

class ZeemanTerm final : public CentreFreeTerm {
 public:
  std::string_view name() const override { return "zeeman"; }
  std::string_view equation() const override { return "eq. 4.70"; }
  std::string_view title() const override { return "Zeeman"; }
  TermValue evaluate(const TermState& s, TermGradient* /*gradient*/) const override {
    if (s.centres.cols() == 0) return {};
    return {mm::zeeman_energy(s.model, s.centres, s.magnetizations), 0.0};
  }
};

class SelfTerm final : public CentreFreeTerm {
 public:
  std::string_view name() const override { return "self"; }
  std::string_view equation() const override { return "eq. 4.76"; }
  std::string_view title() const override { return "magnetic self"; }
  TermValue evaluate(const TermState& s, TermGradient* /*gradient*/) const override {
    if (s.centres.cols() == 0) return {};
    return {mm::self_energy(s.model, s.centres, s.magnetizations), 0.0};
  }
};

// Eq. 4.73: the dissertation's approximation, for comparison with its energy plots; not the
// potential of the forces (magnetic_energy.hpp), so not in the total.
class SelfLinearizedTerm final : public CentreFreeTerm {
 public:
  std::string_view name() const override { return "self_linearized"; }
  std::string_view equation() const override { return "eq. 4.73"; }
  std::string_view title() const override { return "magnetic self, linearized"; }
  bool in_total() const override { return false; }
  TermValue evaluate(const TermState& s, TermGradient* /*gradient*/) const override {
    if (s.centres.cols() == 0) return {};
    mm::MagneticModel linearized = s.model;
    linearized.self_energy = mm::SelfEnergyForm::linearized;
    return {mm::self_energy(linearized, s.centres, s.magnetizations), 0.0};
  }
};

class DipoleTerm final : public EnergyTerm {
 public:
  std::string_view name() const override { return "dipole"; }
  std::string_view equation() const override { return "eq. 4.71"; }
  std::string_view title() const override { return "dipole-dipole"; }
  TermValue evaluate(const TermState& s, TermGradient* gradient) const override {
    if (s.centres.cols() == 0) return {};
    if (gradient != nullptr)
      gradient->centres += mm::dipole_gradient(s.model, s.pairs, s.magnetizations);
    return {mm::dipole_energy(s.model, s.pairs, s.magnetizations), 0.0};
  }
};

template <class Term>
TermRegistration built_in(const char* name, double order) {
  return {.name = name,
          .order = order,
          .always_present = true,
          .read = {},
          .make = [](const TermContext&, const std::any&) { return std::make_unique<Term>(); }};
}

const EnergyTermRegistrar zeeman(built_in<ZeemanTerm>("zeeman", 30));
const EnergyTermRegistrar dipole(built_in<DipoleTerm>("dipole", 40));
const EnergyTermRegistrar self(built_in<SelfTerm>("self", 50));
const EnergyTermRegistrar self_linearized(built_in<SelfLinearizedTerm>("self_linearized", 60));

}  // namespace
}  // namespace mresim::mess
