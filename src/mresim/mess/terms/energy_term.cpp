#include "mresim/mess/terms/energy_term.hpp"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>

namespace mresim::mess {

TermGradient TermGradient::zero(const TermState& state) {
  return {Eigen::Matrix3Xd::Zero(3, state.positions.cols()),
          Eigen::Matrix3Xd::Zero(3, state.centres.cols())};
}

void EnergyTerm::add_hessian_product(const TermState& state, const TermGradient& v,
                                     TermGradient& out) const {
  const double v_max = std::max(v.nodes.cols() > 0 ? v.nodes.cwiseAbs().maxCoeff() : 0.0,
                                v.centres.cols() > 0 ? v.centres.cwiseAbs().maxCoeff() : 0.0);
  if (!(v_max > 0.0)) return;
  // Central differences of the gradient; the step is a small fraction of l_e so that the
  // truncation error (h / scale)^2 and the rounding error eps scale / h are both about 1e-10.
  const double h = 1e-5 * state.lattice.element_length / v_max;
  const auto gradient_at = [&](double t) {
    const Eigen::Matrix3Xd x = state.positions + t * v.nodes;
    const Eigen::Matrix3Xd c = state.centres + t * v.centres;
    const magnetism::PairList pairs =
        c.cols() > 1 ? magnetism::OpenBoundary{}.pairs(c) : magnetism::PairList{};
    const TermState shifted{state.lattice,        x,           c,
                            state.magnetizations, state.model, state.applied_forces,
                            state.settings,       pairs};
    TermGradient g = TermGradient::zero(shifted);
    (void)evaluate(shifted, &g);
    return g;
  };
  const TermGradient plus = gradient_at(h);
  const TermGradient minus = gradient_at(-h);
  out.nodes += (plus.nodes - minus.nodes) / (2.0 * h);
  out.centres += (plus.centres - minus.centres) / (2.0 * h);
}

void EnergyTerm::add_hessian_blocks(const TermState& /*state*/, HessianBlockSink& /*sink*/) const {
  throw std::logic_error("EnergyTerm '" + std::string(name()) +
                         "': no sparse Hessian entries (only the elastic terms have them)");
}

// ------------------------------------------------------------------------------ registry

namespace {

std::vector<TermRegistration>& registry() {
  static std::vector<TermRegistration> terms;
  return terms;
}

}  // namespace

void register_energy_term(TermRegistration registration) {
  std::vector<TermRegistration>& terms = registry();
  const bool duplicate = std::any_of(terms.begin(), terms.end(), [&](const TermRegistration& t) {
    return t.name == registration.name;
  });
  if (duplicate || registration.name.empty() || !registration.make ||
      (!registration.always_present && !registration.read)) {
    // A build mistake, found at start-up: no run could be trusted.
    std::fprintf(stderr, "mresim: energy term '%s' registered twice or incompletely\n",
                 registration.name.c_str());
    std::abort();
  }
  terms.push_back(std::move(registration));
  std::stable_sort(terms.begin(), terms.end(),
                   [](const TermRegistration& a, const TermRegistration& b) {
                     return a.order != b.order ? a.order < b.order : a.name < b.name;
                   });
}

const std::vector<TermRegistration>& energy_term_registrations() { return registry(); }

const TermRegistration* find_energy_term(std::string_view name) {
  for (const TermRegistration& t : registry()) {
    if (t.name == name) return &t;
  }
  return nullptr;
}

std::vector<TermSpec> read_term_tables(const config::TableReader& root) {
  std::vector<TermSpec> out;
  const std::optional<config::TableReader> terms = root.optional_table("terms");
  if (!terms) return out;
  for (const TermRegistration& t : registry()) {
    if (t.always_present) continue;
    // optional_table() records the name as known, so a misspelt [terms.NAME] is refused with
    // the registered names as the allowed ones.
    if (const auto table = terms->optional_table(t.name)) out.push_back({t.name, t.read(*table)});
  }
  return out;
}

std::vector<std::unique_ptr<EnergyTerm>> make_energy_terms(const TermContext& context,
                                                           const std::vector<TermSpec>& optional) {
  for (const TermSpec& s : optional) {
    const TermRegistration* t = find_energy_term(s.name);
    if (t == nullptr || t->always_present) {
      throw std::invalid_argument("make_energy_terms: '" + s.name +
                                  "' is not an optional energy term");
    }
  }
  std::vector<std::unique_ptr<EnergyTerm>> out;
  for (const TermRegistration& t : registry()) {
    if (t.always_present) {
      out.push_back(t.make(context, std::any{}));
      continue;
    }
    for (const TermSpec& s : optional) {
      if (s.name == t.name) out.push_back(t.make(context, s.parameters));
    }
  }
  return out;
}

}  // namespace mresim::mess
