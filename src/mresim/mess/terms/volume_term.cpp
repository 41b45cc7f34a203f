// The volume term, eq. 4.64 x V0, as an EnergyTerm (always present). Its force factor is the
// profile's volume_force_factor (1 physical, 4 seed; terms/elastic_terms.hpp), read from the
// system's settings at every call because solvers may edit them.

#include "mresim/mess/terms/elastic_terms.hpp"
#include "mresim/mess/terms/energy_term.hpp"

namespace mresim::mess {
namespace {

class VolumeTerm final : public EnergyTerm {
 public:
  explicit VolumeTerm(const lattice::Lattice& lattice) : kernel_(lattice) {}

  std::string_view name() const override { return "volume"; }
  std::string_view equation() const override { return "eq. 4.64"; }
  std::string_view title() const override { return "volume elements"; }
  double force_factor(const TermState& s) const override {
    return s.settings.elastic.volume_force_factor;
  }

  TermValue evaluate(const TermState& s, TermGradient* gradient) const override {
    const ElasticValue v = kernel_.evaluate(s.lattice, s.positions, force_factor(s),
                                            gradient ? &gradient->nodes : nullptr);
    return {v.energy, v.rounding};
  }
  HessianKind hessian_kind() const override { return HessianKind::exact; }
  void add_hessian_product(const TermState& s, const TermGradient& v,
                           TermGradient& out) const override {
    kernel_.add_hessian_product(s.lattice, s.positions, force_factor(s), v.nodes, out.nodes);
  }
  bool has_hessian_entries() const override { return true; }
  void add_hessian_blocks(const TermState& s, HessianBlockSink& sink) const override {
    VolumeKernel::add_hessian_blocks(s.lattice, s.positions, force_factor(s), sink);
  }

 private:
  VolumeKernel kernel_;
};

const EnergyTermRegistrar volume_term_registrar({.name = "volume",
                                                 .order = 20,
                                                 .always_present = true,
                                                 .read = {},
                                                 .make = [](const TermContext& c, const std::any&) {
                                                   return std::make_unique<VolumeTerm>(c.lattice);
                                                 }});

}  // namespace
}  // namespace mresim::mess
