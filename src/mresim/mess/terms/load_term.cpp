// The load term as an EnergyTerm (always present; zero without applied forces): the potential
// energy of the applied nodal forces f (N, 3 x N), E = -sum_n f_n . (x_n - x0_n) with x0 the
// lattice's initial positions. Gradient -f; Hessian zero (f does not depend on x).

#include "mresim/mess/system/fixed_order.hpp"
#include "mresim/mess/terms/energy_term.hpp"

namespace mresim::mess {
namespace {

class LoadTerm final : public EnergyTerm {
 public:
  std::string_view name() const override { return "load"; }
  std::string_view equation() const override { return "-sum f.(x - x0)"; }
  std::string_view title() const override { return "applied load"; }

  TermValue evaluate(const TermState& s, TermGradient* gradient) const override {
    const Eigen::Matrix3Xd& f = s.applied_forces;
    if (f.cols() == 0) return {};
    const Eigen::Matrix3Xd& x0 = s.lattice.positions;
    const double energy = -detail::fixed_order_sum(s.lattice.node_count(), [&](std::int64_t n) {
      return f.col(n).dot(s.positions.col(n) - x0.col(n));
    });
    if (gradient != nullptr) gradient->nodes -= f;
    return {energy, 0.0};
  }
  HessianKind hessian_kind() const override { return HessianKind::zero; }
  void add_hessian_product(const TermState& /*state*/, const TermGradient& /*v*/,
                           TermGradient& /*out*/) const override {}
};

const EnergyTermRegistrar load_term_registrar({.name = "load",
                                               .order = 80,
                                               .always_present = true,
                                               .read = {},
                                               .make = [](const TermContext&, const std::any&) {
                                                 return std::make_unique<LoadTerm>();
                                               }});

}  // namespace
}  // namespace mresim::mess
