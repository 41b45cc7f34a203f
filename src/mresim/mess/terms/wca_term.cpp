// The WCA repulsion between particle centres, eqs. 4.79-4.80, as an EnergyTerm (always
// present; zero without particles or with E_max = 0). Independent of M. Exact Hessian: per
// pair at distance S along u = r/S, H = E''(S) u u^T + (E'(S)/S) (I - u u^T), with +H on the
// (i, i) and (j, j) blocks and -H on (i, j), (j, i).

#include "mresim/mess/terms/energy_term.hpp"

namespace mresim::mess {
namespace {

namespace mm = mresim::magnetism;

class WcaTerm final : public EnergyTerm {
 public:
  std::string_view name() const override { return "wca"; }
  std::string_view equation() const override { return "eq. 4.79"; }
  std::string_view title() const override { return "WCA"; }

  TermValue evaluate(const TermState& s, TermGradient* gradient) const override {
    if (s.centres.cols() == 0) return {};
    if (gradient != nullptr) {
      gradient->centres += mm::wca_gradient(s.model, s.pairs, static_cast<int>(s.centres.cols()));
    }
    return {mm::wca_energy(s.model, s.pairs), 0.0};
  }

  HessianKind hessian_kind() const override { return HessianKind::exact; }
  void add_hessian_product(const TermState& s, const TermGradient& v,
                           TermGradient& out) const override {
    for (const mm::ParticlePair& p : s.pairs) {
      const double distance = p.r.norm();
      const mm::WcaValue e = mm::wca_pair(s.model.wca, distance);
      if (e.derivative == 0.0) continue;  // beyond the cut-off
      const Eigen::Vector3d u = p.r / distance;
      const Eigen::Vector3d dv = v.centres.col(p.i) - v.centres.col(p.j);
      const double along = u.dot(dv);
      const Eigen::Vector3d hv = mm::wca_pair_curvature(s.model.wca, distance) * along * u +
                                 (e.derivative / distance) * (dv - along * u);
      out.centres.col(p.i) += hv;
      out.centres.col(p.j) -= hv;
    }
  }
};

const EnergyTermRegistrar wca_term_registrar({.name = "wca",
                                              .order = 70,
                                              .always_present = true,
                                              .read = {},
                                              .make = [](const TermContext&, const std::any&) {
                                                return std::make_unique<WcaTerm>();
                                              }});

}  // namespace
}  // namespace mresim::mess
