// The system as a list of energy terms: the built-in terms in their order, energies and
// gradient equal to the serial reference formulas (elastic_terms.hpp, magnetic_energy.hpp) as
// the fixed code path combined them, the potential of the seed profile, copies, and the
// system's Hessian product against differences of its gradient at fixed M.

#include <gtest/gtest.h>

#include "../support/mess_test_support.hpp"
#include "mresim/mess/system/system_energy.hpp"

namespace mess = mresim::mess;
namespace lat = mresim::lattice;
namespace mm = mresim::magnetism;
using mess::testing::perturbed;
using mess::testing::small_lattice;
using mess::testing::tesla;

namespace {

mess::MessSystem deformed_system(const char* profile) {
  const mess::ModelProfile& p = mess::model_profile(profile);
  mess::MessSystem sys = mess::MessSystem::make(
      small_lattice(p, {6, 6, 10}, {{2, 2, 2}, {3, 3, 6}}), tesla(0.02, 0.0, 0.09), p);
  sys.set_positions(perturbed(sys.lattice().positions, 0.03 * sys.length_scale(), 5));
  Eigen::Matrix3Xd f = Eigen::Matrix3Xd::Zero(3, sys.node_count());
  f(2, 7) = 2e-9;
  f(0, 40) = -1e-9;
  sys.set_applied_forces(f);
  return sys;
}

}  // namespace

TEST(MessTermList, BuiltInTermsInOrder) {
  const mess::MessSystem sys = deformed_system("physical");
  std::vector<std::string> names;
  for (const auto& t : sys.terms()) names.emplace_back(t->name());
  EXPECT_EQ(names, (std::vector<std::string>{"springs", "volume", "zeeman", "dipole", "self",
                                             "self_linearized", "wca", "load"}));
  EXPECT_FALSE(sys.terms()[5]->in_total());
  EXPECT_EQ((*sys.energy_labels())[0].equation, "eq. 4.62");
  const mess::MessSystem copy = sys;  // copies rebuild their terms
  EXPECT_EQ(copy.terms().size(), sys.terms().size());
  EXPECT_NE(copy.terms()[0].get(), sys.terms()[0].get());
}

TEST(MessTermList, EnergiesAndGradientEqualTheReferenceFormulas) {
  for (const char* profile : {"physical", "seed"}) {
    mess::MessSystem sys = deformed_system(profile);
    Eigen::Matrix3Xd g;
    const mess::Evaluation ev = sys.evaluate(&g);
    const mess::MessEnergies& e = ev.energies;
    const lat::Lattice& l = sys.lattice();
    const Eigen::Matrix3Xd& x = sys.positions();
    const Eigen::Matrix3Xd c = sys.particle_centres();
    const Eigen::Matrix3Xd& M = sys.magnetizations();
    const double factor = sys.settings().elastic.volume_force_factor;
    // Magnetic terms: bitwise what magnetic_energies() returns.
    const mm::MagneticEnergyBreakdown b = mm::magnetic_energies(sys.model(), c, M);
    EXPECT_EQ(e["zeeman"], b.zeeman);
    EXPECT_EQ(e["dipole"], b.dipole);
    EXPECT_EQ(e["self"], b.self);
    EXPECT_EQ(e["wca"], b.wca);
    // Elastic terms: the serial formulas (a different summation order: 1e-12).
    const double springs = mess::spring_energy(l.springs, x);
    const double volume = mess::volume_energy(l.elements, l.polymer.kappa, l.element_length, x);
    EXPECT_NEAR(e["springs"], springs, 1e-12 * springs);
    EXPECT_NEAR(e["volume"], volume, 1e-12 * volume);
    double load = 0.0;
    for (Eigen::Index n = 0; n < l.node_count(); ++n) {
      load -= sys.applied_forces().col(n).dot(x.col(n) - l.positions.col(n));
    }
    EXPECT_NEAR(e["load"], load, 1e-12 * std::abs(load));
    EXPECT_EQ(e.total(), e["springs"] + e["volume"] + e["zeeman"] + e["dipole"] + e["self"] +
                             e["wca"] + e["load"]);
    EXPECT_EQ(ev.potential, e.total() + (factor - 1.0) * e["volume"]) << profile;
    // Gradient: elastic + volume factor, minus the applied forces, centre terms spread.
    Eigen::Matrix3Xd ref = Eigen::Matrix3Xd::Zero(3, l.node_count());
    mess::add_spring_gradient(l.springs, x, ref);
    mess::add_volume_gradient(l.elements, l.polymer.kappa, l.element_length, x, ref, factor);
    ref -= sys.applied_forces();
    const Eigen::Matrix3Xd gc = mm::magnetic_gradient(sys.model(), c, M);
    for (std::size_t p = 0; p < l.particle_nodes.size(); ++p) {
      for (const std::int32_t n : l.particle_nodes[p]) {
        ref.col(n) += gc.col(static_cast<Eigen::Index>(p)) / l.particle_nodes[p].size();
      }
    }
    EXPECT_LT((g - ref).cwiseAbs().maxCoeff(), 1e-12 * ref.cwiseAbs().maxCoeff()) << profile;
    EXPECT_TRUE(sys.centre_gradient().isApprox(gc, 1e-14));
  }
}

TEST(MessTermList, HessianProductMatchesDifferencesOfTheGradientAtFixedM) {
  mess::MessSystem sys = deformed_system("physical");
  (void)sys.evaluate(nullptr);  // solve M once, then keep it
  sys.settings().magnetization_update = mess::MagnetizationUpdate::manual;
  const Eigen::Matrix3Xd x = sys.positions();
  const Eigen::Matrix3Xd v = perturbed(Eigen::Matrix3Xd::Zero(3, x.cols()), 1.0, 17);
  const Eigen::Matrix3Xd hv = sys.hessian_product(v);
  const double h = 1e-6 * sys.length_scale();
  const auto gradient = [&](const Eigen::Matrix3Xd& y) {
    sys.set_positions(y);
    Eigen::Matrix3Xd g;
    (void)sys.evaluate(&g);
    return g;
  };
  const Eigen::Matrix3Xd fd = (gradient(x + h * v) - gradient(x - h * v)) / (2.0 * h);
  EXPECT_LT((hv - fd).cwiseAbs().maxCoeff(), 1e-6 * fd.cwiseAbs().maxCoeff());
  // The sparse elastic Hessian is the product of the elastic terms.
  sys.set_positions(x);
  const Eigen::SparseMatrix<double> H = sys.elastic_hessian();
  EXPECT_EQ(H.rows(), 3 * sys.node_count());
  const Eigen::Index n = H.rows();
  const Eigen::VectorXd assembled = H * Eigen::Map<const Eigen::VectorXd>(v.data(), n);
  EXPECT_GT(assembled.norm(), 0.0);
  const Eigen::Map<const Eigen::VectorXd> product(hv.data(), n);
  // The difference is the magnetic part: only nodes of particles.
  Eigen::VectorXd magnetic = product - assembled;
  for (const auto& nodes : sys.lattice().particle_nodes) {
    for (const std::int32_t k : nodes) magnetic.segment<3>(3 * k).setZero();
  }
  EXPECT_LT(magnetic.cwiseAbs().maxCoeff(), 1e-12 * product.cwiseAbs().maxCoeff());
}
