// The contract every registered energy term of the 3D model keeps (terms/energy_term.hpp),
// checked by iterating the registry, so a new term is tested by adding its data file
// tests/data/terms/<name>.json (docs/energy-terms-3d.md#the-term-contract-test):
//
// - its gradient with respect to node positions and particle centres equals central
//   differences of its energy (times its force factor), with the particles apart and with two
//   of them near contact, inside the WCA range;
// - its Hessian-vector product equals central differences of its gradient, and its sparse
//   Hessian entries (elastic terms) give the same product;
// - energy, gradient and Hessian product are bitwise the same on 1 and 2 OpenMP threads;
// - energy and gradient at a few named nodes and at every particle equal the reference values
//   of its data file (regenerate: MRESIM_REGENERATE_TERM_DATA=1, see the data files' header).
//
// The state (ContractState below) is a 10 x 10 x 15-node physical- or seed-profile lattice
// with three particles of order 1 (R = 1.5 um = 1.5 l_e), nodes moved randomly by up to
// 0.05 l_e, arbitrary magnetizations of 0.2-0.6 Ms, a field of (10, -20, 50) mT and random
// applied node forces. Changing it changes every reference value: regenerate the data files.

#include <gtest/gtest.h>
#include <omp.h>

#include <Eigen/SparseCore>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <random>
#include <string>
#include <vector>

#include "../../support/json_file.hpp"
#include "../support/finite_differences.hpp"
#include "../support/mess_test_support.hpp"
#include "mresim/config/table_reader.hpp"
#include "mresim/mess/profile/model_profile.hpp"
#include "mresim/mess/terms/energy_term.hpp"

namespace {

namespace fs = std::filesystem;
namespace mm = mresim::magnetism;
namespace ms = mresim::mess;
namespace mt = mresim::mess::testing;
using mresim::testing::read_json;
using nlohmann::json;

const fs::path kTermData = fs::path(MRESIM_SOURCE_DIR) / "tests/data/terms";
constexpr double kEps = std::numeric_limits<double>::epsilon();

// The [terms.<name>] table of an optional term, from its data file ("" if there is none).
std::string term_table(const std::string& name) {
  const fs::path file = kTermData / (name + ".json");
  if (!fs::exists(file)) return "";
  return read_json(file).value("table", std::string());
}

struct ContractState {
  mresim::lattice::Lattice lattice;
  mm::MagneticModel model;
  ms::MessSettings settings;
  Eigen::Matrix3Xd positions, magnetizations, applied_forces;
  Eigen::Matrix3Xd loose, near_contact;  // two sets of centres
  std::vector<std::unique_ptr<ms::EnergyTerm>> terms;

  explicit ContractState(const std::string& profile_name) {
    const ms::ModelProfile& profile = ms::model_profile(profile_name);
    lattice = mt::small_lattice(profile, {9, 9, 14}, {{3, 3, 3}, {5, 5, 7}, {3, 5, 11}});
    const mm::MagneticParticles particles{};  // R = 1.5 um, chi0 = 70, Ms = 1.6e6 A/m
    model = mm::MagneticModel::make(particles, mt::tesla(0.01, -0.02, 0.05),
                                    profile.wca_scale_ms(particles.Ms));
    settings = profile.system_settings();
    const double l_e = lattice.element_length;
    positions = mt::perturbed(lattice.positions, 0.05 * l_e);
    applied_forces = mt::perturbed(Eigen::Matrix3Xd::Zero(3, positions.cols()), 1e-10, 11);
    const auto np = static_cast<Eigen::Index>(lattice.particle_count());
    loose.resize(3, np);
    magnetizations.resize(3, np);
    for (Eigen::Index i = 0; i < np; ++i) {
      loose.col(i) = lattice.particle_centres[static_cast<std::size_t>(i)];
      const auto t = static_cast<double>(i);
      magnetizations.col(i) =
          particles.Ms * Eigen::Vector3d(0.2 * std::cos(t), 0.15 - 0.1 * t, 0.4 + 0.1 * t);
    }
    loose = mt::perturbed(loose, 0.01 * l_e, 3);
    // Particle 1 at 2.1 R from particle 0: inside the WCA range (r_cut = 2^(1/6) (2R + 0.1 um)).
    near_contact = loose;
    near_contact.col(1) =
        loose.col(0) + 2.1 * particles.radius * Eigen::Vector3d(1.0, 0.3, 0.8).normalized();
    terms = make_terms();
  }

  // Every always-present term and every optional one with the table of its data file.
  std::vector<std::unique_ptr<ms::EnergyTerm>> make_terms() const {
    std::string toml;
    for (const auto& r : ms::energy_term_registrations()) {
      if (!r.always_present) toml += "[terms." + r.name + "]\n" + term_table(r.name) + "\n";
    }
    const auto root = mresim::config::TableReader::parse_string(toml, "contract.toml");
    const ms::TermContext context{lattice, model, settings};
    return ms::make_energy_terms(context, ms::read_term_tables(root));
  }
};

// A term evaluated at (x, c) with the pair list of c.
struct Evaluation {
  ms::TermValue value;
  ms::TermGradient gradient;
};

Evaluation evaluate(const ContractState& s, const ms::EnergyTerm& term, const Eigen::Matrix3Xd& x,
                    const Eigen::Matrix3Xd& c) {
  const mm::PairList pairs = c.cols() > 1 ? mm::OpenBoundary{}.pairs(c) : mm::PairList{};
  const ms::TermState state{s.lattice,        x,          c,    s.magnetizations, s.model,
                            s.applied_forces, s.settings, pairs};
  Evaluation e{{}, ms::TermGradient::zero(state)};
  e.value = term.evaluate(state, &e.gradient);
  return e;
}

ms::TermGradient hessian_product(const ContractState& s, const ms::EnergyTerm& term,
                                 const Eigen::Matrix3Xd& c, const ms::TermGradient& v) {
  const mm::PairList pairs = c.cols() > 1 ? mm::OpenBoundary{}.pairs(c) : mm::PairList{};
  const ms::TermState state{s.lattice, s.positions,      c,          s.magnetizations,
                            s.model,   s.applied_forces, s.settings, pairs};
  ms::TermGradient out = ms::TermGradient::zero(state);
  term.add_hessian_product(state, v, out);
  return out;
}

double max_abs_or_zero(const Eigen::Matrix3Xd& m) {
  return m.size() > 0 ? m.cwiseAbs().maxCoeff() : 0.0;
}

// Nodes whose gradient the tests look at: corners of the box, particle nodes and their
// neighbours, and 40 random ones.
std::vector<Eigen::Index> probe_nodes(const ContractState& s) {
  const Eigen::Index n = s.positions.cols();
  std::vector<Eigen::Index> out{0, 1, n / 2, n - 1};
  for (const auto& nodes : s.lattice.particle_nodes) {
    out.push_back(nodes.front());
    out.push_back(std::min<Eigen::Index>(nodes.back() + 1, n - 1));
  }
  std::mt19937 gen(5);
  std::uniform_int_distribution<Eigen::Index> pick(0, n - 1);
  for (int k = 0; k < 40; ++k) out.push_back(pick(gen));
  return out;
}

std::vector<Eigen::Index> coordinates_of(const std::vector<Eigen::Index>& nodes) {
  std::vector<Eigen::Index> out;
  for (const Eigen::Index n : nodes) {
    for (int a = 0; a < 3; ++a) out.push_back(3 * n + a);
  }
  return out;
}

class TermContract : public ::testing::TestWithParam<std::string> {
 protected:
  static const ContractState& state() {
    static const std::map<std::string, std::unique_ptr<ContractState>> states = [] {
      std::map<std::string, std::unique_ptr<ContractState>> m;
      for (const char* p : {"physical", "seed"}) m[p] = std::make_unique<ContractState>(p);
      return m;
    }();
    return *states.at(GetParam());
  }
};

// Step h = 1e-4 l_e: truncation (h / scale)^2 <= 1e-7 for terms that vary on the scale of the
// WCA range (0.3 l_e) or faster than l_e; rounding eps (|E| + rounding) / h, kept 100 times.
// Tolerance: 1e-6 of the largest gradient entry plus that rounding bound.
void expect_gradient_matches(const ContractState& s, const ms::EnergyTerm& term,
                             const Eigen::Matrix3Xd& centres, const char* where) {
  const Evaluation e = evaluate(s, term, s.positions, centres);
  if (!term.in_total()) {  // reported only: no gradient (energy_term.hpp)
    EXPECT_EQ(max_abs_or_zero(e.gradient.nodes) + max_abs_or_zero(e.gradient.centres), 0.0)
        << term.name();
    return;
  }
  const double h = 1e-4 * s.lattice.element_length;
  const double factor = term.force_factor({s.lattice,
                                           s.positions,
                                           centres,
                                           s.magnetizations,
                                           s.model,
                                           s.applied_forces,
                                           s.settings,
                                           {}});
  const double rounding = 100.0 * kEps * (std::abs(e.value.energy) + e.value.rounding) / h;
  const double scale =
      std::max(max_abs_or_zero(e.gradient.nodes), max_abs_or_zero(e.gradient.centres));
  const double tolerance = 1e-6 * scale + factor * rounding;
  const auto nodes = coordinates_of(probe_nodes(s));
  const auto fd_x = mt::central_differences(
      [&](const Eigen::Matrix3Xd& x) { return evaluate(s, term, x, centres).value.energy; },
      s.positions, nodes, h);
  for (std::size_t k = 0; k < nodes.size(); ++k) {
    EXPECT_NEAR(e.gradient.nodes.data()[nodes[k]], factor * fd_x[k], tolerance)
        << term.name() << " (" << where << "), node coordinate " << nodes[k];
  }
  const Eigen::Matrix3Xd fd_c = mt::central_difference_gradient(
      [&](const Eigen::Matrix3Xd& c) { return evaluate(s, term, s.positions, c).value.energy; },
      centres, h);
  for (Eigen::Index k = 0; k < centres.size(); ++k) {
    EXPECT_NEAR(e.gradient.centres.data()[k], factor * fd_c.data()[k], tolerance)
        << term.name() << " (" << where << "), centre coordinate " << k;
  }
}

TEST_P(TermContract, GradientIsCentralDifferencesOfTheEnergy) {
  const ContractState& s = state();
  ASSERT_FALSE(s.terms.empty());
  for (const auto& term : s.terms) {
    expect_gradient_matches(s, *term, s.loose, "particles apart");
    expect_gradient_matches(s, *term, s.near_contact, "near contact");
  }
}

ms::TermGradient some_direction(const ContractState& s, std::uint32_t seed) {
  return {mt::perturbed(Eigen::Matrix3Xd::Zero(3, s.positions.cols()), 1.0, seed),
          mt::perturbed(Eigen::Matrix3Xd::Zero(3, s.loose.cols()), 1.0, seed + 1)};
}

// H v against (g(s + h v) - g(s - h v)) / 2h with h = 1e-4 l_e (the default product uses
// 1e-5 l_e, so the two are different computations). Tolerance: 1e-5 of the largest entry of
// H v (truncation (h / scale)^2 at the WCA range) plus rounding 100 eps |g| / h.
void expect_hessian_product_matches(const ContractState& s, const ms::EnergyTerm& term,
                                    const Eigen::Matrix3Xd& centres, const char* where) {
  if (!term.in_total()) return;
  const ms::TermGradient v = some_direction(s, 21);
  const ms::TermGradient hv = hessian_product(s, term, centres, v);
  const double h = 1e-4 * s.lattice.element_length;
  const auto moved = [&](double t) {
    return evaluate(s, term, s.positions + t * v.nodes, centres + t * v.centres).gradient;
  };
  const ms::TermGradient plus = moved(h);
  const ms::TermGradient minus = moved(-h);
  const Eigen::Matrix3Xd fd_x = (plus.nodes - minus.nodes) / (2.0 * h);
  const Eigen::Matrix3Xd fd_c = (plus.centres - minus.centres) / (2.0 * h);
  const Evaluation e = evaluate(s, term, s.positions, centres);
  const double g_max =
      std::max(max_abs_or_zero(e.gradient.nodes), max_abs_or_zero(e.gradient.centres));
  const double tolerance = 1e-5 * std::max(max_abs_or_zero(hv.nodes), max_abs_or_zero(hv.centres)) +
                           100.0 * kEps * g_max / h;
  EXPECT_LE(max_abs_or_zero(hv.nodes - fd_x), tolerance) << term.name() << " (" << where << ")";
  EXPECT_LE(max_abs_or_zero(hv.centres - fd_c), tolerance) << term.name() << " (" << where << ")";
  if (term.hessian_kind() == ms::HessianKind::zero) {
    EXPECT_EQ(max_abs_or_zero(hv.nodes) + max_abs_or_zero(hv.centres), 0.0) << term.name();
  }
}

TEST_P(TermContract, HessianProductIsCentralDifferencesOfTheGradient) {
  const ContractState& s = state();
  for (const auto& term : s.terms) {
    expect_hessian_product_matches(s, *term, s.loose, "particles apart");
    expect_hessian_product_matches(s, *term, s.near_contact, "near contact");
  }
}

// The sparse entries (elastic terms) times v equal the product, to the rounding of two sums
// in different orders (1e-10 of the largest entry).
TEST_P(TermContract, SparseHessianEntriesGiveTheProduct) {
  const ContractState& s = state();
  int checked = 0;
  for (const auto& term : s.terms) {
    if (!term->has_hessian_entries()) continue;
    ++checked;
    const mm::PairList pairs = mm::OpenBoundary{}.pairs(s.loose);
    const ms::TermState st{s.lattice, s.positions,      s.loose,    s.magnetizations,
                           s.model,   s.applied_forces, s.settings, pairs};
    std::vector<Eigen::Triplet<double>> entries;
    term->add_hessian_entries(st, entries);
    const Eigen::Index n = 3 * s.positions.cols();
    Eigen::SparseMatrix<double> h(n, n);
    h.setFromTriplets(entries.begin(), entries.end());
    ms::TermGradient v = some_direction(s, 31);
    v.centres.setZero();
    const Eigen::VectorXd hv_sparse = h * v.nodes.reshaped();
    const ms::TermGradient hv = hessian_product(s, *term, s.loose, v);
    EXPECT_LE((hv_sparse - hv.nodes.reshaped()).cwiseAbs().maxCoeff(),
              1e-10 * hv_sparse.cwiseAbs().maxCoeff())
        << term->name();
  }
  EXPECT_GT(checked, 0) << "no term has sparse Hessian entries (the elastic terms should)";
}

TEST_P(TermContract, BitwiseIndependentOfTheThreadCount) {
  const ContractState& s = state();
  const int threads = omp_get_max_threads();
  const ms::TermGradient v = some_direction(s, 41);
  for (const auto& term : s.terms) {
    omp_set_num_threads(1);
    const Evaluation one = evaluate(s, *term, s.positions, s.near_contact);
    const ms::TermGradient hv_one = hessian_product(s, *term, s.near_contact, v);
    omp_set_num_threads(2);
    const Evaluation two = evaluate(s, *term, s.positions, s.near_contact);
    const ms::TermGradient hv_two = hessian_product(s, *term, s.near_contact, v);
    omp_set_num_threads(threads);
    EXPECT_EQ(one.value.energy, two.value.energy) << term->name();
    EXPECT_TRUE(one.gradient.nodes == two.gradient.nodes) << term->name();
    EXPECT_TRUE(one.gradient.centres == two.gradient.centres) << term->name();
    EXPECT_TRUE(hv_one.nodes == hv_two.nodes && hv_one.centres == hv_two.centres) << term->name();
  }
}

// ---------------------------------------------------------------- reference values per term

const char* const kRegenerate =
    "MRESIM_REGENERATE_TERM_DATA=1 ./build/mresim_tests --gtest_filter='TermContract*'";

// Nodes named in the data files: box corners and the first node of each particle.
std::vector<Eigen::Index> reference_nodes(const ContractState& s) {
  std::vector<Eigen::Index> out{0, s.positions.cols() / 3, s.positions.cols() - 1};
  for (const auto& nodes : s.lattice.particle_nodes) out.push_back(nodes.front());
  return out;
}

json reference_values(const ContractState& s, const ms::EnergyTerm& term) {
  const Evaluation e = evaluate(s, term, s.positions, s.near_contact);
  json out{{"energy_J", e.value.energy}, {"energy_rounding_J", e.value.rounding}};
  for (const Eigen::Index n : reference_nodes(s)) {
    const Eigen::Vector3d g = e.gradient.nodes.col(n);
    out["nodes"].push_back({{"node", n}, {"gradient_J_per_m", {g.x(), g.y(), g.z()}}});
  }
  for (Eigen::Index i = 0; i < e.gradient.centres.cols(); ++i) {
    const Eigen::Vector3d g = e.gradient.centres.col(i);
    out["centres"].push_back({{"particle", i}, {"gradient_J_per_m", {g.x(), g.y(), g.z()}}});
  }
  return out;
}

void write_reference(const fs::path& file, const std::string& name, const std::string& profile,
                     const json& values) {
  json data = fs::exists(file) ? read_json(file) : json::object();
  data["about"] = {
      "Reference energy and gradient of the energy term '" + name + "' in the contract state " +
          "of tests/mess/contract/term_contract_test.cpp (ContractState, centres near contact), " +
          "per model profile; gradients include the term's force factor.",
      "Checked to 1e-12 relative (energy: of |E| + its rounding estimate; gradients: of the " +
          std::string("largest entry listed), the allowance of a refactor that reorders sums."),
      std::string("Regenerate after a deliberate change of the term or of the state: ") +
          kRegenerate + " (docs/energy-terms-3d.md#the-term-contract-test)."};
  data["term"] = name;
  data["profiles"][profile] = values;
  std::ofstream(file) << data.dump(2) << "\n";
}

void expect_close(const json& got, const json& want, double scale, const std::string& what) {
  for (std::size_t a = 0; a < 3; ++a) {
    EXPECT_NEAR(got[a].get<double>(), want[a].get<double>(), 1e-12 * scale)
        << what << "[" << a << "]";
  }
}

TEST_P(TermContract, ValuesMatchTheReferenceDataFile) {
  const ContractState& s = state();
  const bool regenerate = std::getenv("MRESIM_REGENERATE_TERM_DATA") != nullptr;
  for (const auto& term : s.terms) {
    const std::string name(term->name());
    const fs::path file = kTermData / (name + ".json");
    const json got = reference_values(s, *term);
    if (regenerate) write_reference(file, name, GetParam(), got);
    ASSERT_TRUE(fs::exists(file)) << "no reference data for term '" << name << "': run "
                                  << kRegenerate;
    const json want = read_json(file).at("profiles").at(GetParam());
    const double e = want.at("energy_J").get<double>();
    EXPECT_NEAR(got["energy_J"].get<double>(), e,
                1e-12 * (std::abs(e) + want.at("energy_rounding_J").get<double>()))
        << name;
    double scale = 0.0;
    for (const auto* part : {"nodes", "centres"}) {
      for (const auto& row : want.at(part)) {
        for (const auto& g : row.at("gradient_J_per_m"))
          scale = std::max(scale, std::abs(g.get<double>()));
      }
    }
    ASSERT_EQ(got["nodes"].size(), want.at("nodes").size()) << name;
    for (std::size_t k = 0; k < want.at("nodes").size(); ++k) {
      EXPECT_EQ(got["nodes"][k]["node"], want["nodes"][k]["node"]) << name;
      expect_close(got["nodes"][k]["gradient_J_per_m"], want["nodes"][k]["gradient_J_per_m"], scale,
                   name + " node " + want["nodes"][k]["node"].dump());
    }
    ASSERT_EQ(got["centres"].size(), want.at("centres").size()) << name;
    for (std::size_t k = 0; k < want.at("centres").size(); ++k) {
      expect_close(got["centres"][k]["gradient_J_per_m"], want["centres"][k]["gradient_J_per_m"],
                   scale, name + " particle " + std::to_string(k));
    }
  }
}

INSTANTIATE_TEST_SUITE_P(TermContract, TermContract, ::testing::Values("physical", "seed"),
                         [](const auto& info) { return info.param; });

// Every registered term is in the contract: optional ones through their data file's table.
TEST(TermContractCoverage, EveryRegisteredTermIsBuiltAndHasReferenceData) {
  const ContractState s("physical");
  EXPECT_EQ(s.terms.size(), ms::energy_term_registrations().size());
  // The near-contact state is inside the WCA range, the loose one outside.
  EXPECT_LT((s.near_contact.col(1) - s.near_contact.col(0)).norm(), s.model.wca.r_cut());
  EXPECT_GT((s.loose.col(1) - s.loose.col(0)).norm(), s.model.wca.r_cut());
  for (const auto& r : ms::energy_term_registrations()) {
    EXPECT_TRUE(fs::exists(kTermData / (r.name + ".json")))
        << "term '" << r.name << "': add tests/data/terms/" << r.name << ".json"
        << (r.always_present ? "" : " with its \"table\"") << ", then run " << kRegenerate;
  }
}

}  // namespace
