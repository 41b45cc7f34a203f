// The springs term, eq. 4.62, as an EnergyTerm (always present).

#include "mresim/mess/terms/elastic_terms.hpp"
#include "mresim/mess/terms/energy_term.hpp"

namespace mresim::mess {
namespace {

class SpringsTerm final : public EnergyTerm {
 public:
  explicit SpringsTerm(const lattice::Lattice& lattice) : kernel_(lattice) {}

  std::string_view name() const override { return "springs"; }
  std::string_view equation() const override { return "eq. 4.62"; }
  std::string_view title() const override { return "springs"; }

  TermValue evaluate(const TermState& s, TermGradient* gradient) const override {
    const ElasticValue v =
        kernel_.evaluate(s.lattice, s.positions, gradient ? &gradient->nodes : nullptr);
    return {v.energy, v.rounding};
  }
  HessianKind hessian_kind() const override { return HessianKind::exact; }
  void add_hessian_product(const TermState& s, const TermGradient& v,
                           TermGradient& out) const override {
    kernel_.add_hessian_product(s.lattice, s.positions, v.nodes, out.nodes);
  }
  bool has_hessian_entries() const override { return true; }
  void add_hessian_blocks(const TermState& s, HessianBlockSink& sink) const override {
    SpringKernel::add_hessian_blocks(s.lattice, s.positions, sink);
  }

 private:
  SpringKernel kernel_;
};

const EnergyTermRegistrar springs_term_registrar({.name = "springs",
                                                  .order = 10,
                                                  .always_present = true,
                                                  .read = {},
                                                  .make = [](const TermContext& c,
                                                             const std::any&) {
                                                    return std::make_unique<SpringsTerm>(c.lattice);
                                                  }});

}  // namespace
}  // namespace mresim::mess
