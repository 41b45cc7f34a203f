// Hessians of the elastic terms (springs eq. 4.62, volume eq. 4.64) and of WCA (eq. 4.79):
// the exact Hessian-vector products against central differences of the exact gradients, in a
// random, a sheared and a compressed state; the sparse assembly against the product on random
// vectors, its symmetry, and the products' independence of the thread count.

#include <gtest/gtest.h>
#include <omp.h>

#include <Eigen/SparseCore>
#include <cstring>
#include <random>
#include <utility>
#include <vector>

#include "../support/mess_test_support.hpp"
#include "mresim/mess/terms/elastic_terms.hpp"
#include "mresim/mess/terms/energy_term.hpp"

namespace mess = mresim::mess;
namespace lat = mresim::lattice;
namespace mm = mresim::magnetism;
using mess::testing::perturbed;
using mess::testing::small_lattice;

namespace {

Eigen::Matrix3Xd random_direction(Eigen::Index n, std::uint32_t seed) {
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::Matrix3Xd v(3, n);
  for (Eigen::Index k = 0; k < v.size(); ++k) v.data()[k] = u(gen);
  return v;
}

// The three states: random displacements, simple shear (x += 0.1 z) and 5 % compression along
// z, each with a small random perturbation so that nothing is symmetric.
std::vector<Eigen::Matrix3Xd> states(const lat::Lattice& l) {
  const double le = l.element_length;
  Eigen::Matrix3Xd sheared = l.positions;
  sheared.row(0) += 0.1 * l.positions.row(2);
  Eigen::Matrix3Xd compressed = l.positions;
  compressed.row(2) *= 0.95;
  return {perturbed(l.positions, 0.05 * le, 3), perturbed(sheared, 0.01 * le, 4),
          perturbed(compressed, 0.01 * le, 5)};
}

// max |a - b| / max |b|.
double relative_max_error(const Eigen::Matrix3Xd& a, const Eigen::Matrix3Xd& b) {
  return (a - b).cwiseAbs().maxCoeff() / b.cwiseAbs().maxCoeff();
}

template <class Gradient>
Eigen::Matrix3Xd difference_of_gradients(Gradient gradient, const Eigen::Matrix3Xd& x,
                                         const Eigen::Matrix3Xd& v, double h) {
  return (gradient(x + h * v) - gradient(x - h * v)) / (2.0 * h);
}

}  // namespace

TEST(MessElasticHessian, SpringProductMatchesDifferencesOfTheGradient) {
  const lat::Lattice l = small_lattice(mess::model_profile("physical"), {5, 5, 6}, {{2, 2, 3}});
  const mess::SpringKernel springs(l);
  for (const Eigen::Matrix3Xd& x : states(l)) {
    const Eigen::Matrix3Xd v = random_direction(l.node_count(), 11);
    Eigen::Matrix3Xd hv = Eigen::Matrix3Xd::Zero(3, l.node_count());
    springs.add_hessian_product(l, x, v, hv);
    const auto gradient = [&](const Eigen::Matrix3Xd& y) {
      Eigen::Matrix3Xd g = Eigen::Matrix3Xd::Zero(3, y.cols());
      mess::add_spring_gradient(l.springs, y, g);
      return g;
    };
    EXPECT_LT(
        relative_max_error(hv, difference_of_gradients(gradient, x, v, 1e-6 * l.element_length)),
        1e-7);
  }
}

TEST(MessElasticHessian, VolumeProductMatchesDifferencesOfTheGradient) {
  const lat::Lattice l = small_lattice(mess::model_profile("physical"), {5, 5, 6}, {{2, 2, 3}});
  const mess::VolumeKernel volume(l);
  for (const double factor : {1.0, 4.0}) {
    for (const Eigen::Matrix3Xd& x : states(l)) {
      const Eigen::Matrix3Xd v = random_direction(l.node_count(), 12);
      Eigen::Matrix3Xd hv = Eigen::Matrix3Xd::Zero(3, l.node_count());
      volume.add_hessian_product(l, x, factor, v, hv);
      const auto gradient = [&](const Eigen::Matrix3Xd& y) {
        Eigen::Matrix3Xd g = Eigen::Matrix3Xd::Zero(3, y.cols());
        mess::add_volume_gradient(l.elements, l.polymer.kappa, l.element_length, y, g, factor);
        return g;
      };
      EXPECT_LT(
          relative_max_error(hv, difference_of_gradients(gradient, x, v, 1e-6 * l.element_length)),
          1e-7)
          << "factor " << factor;
    }
  }
}

TEST(MessElasticHessian, SparseAssemblyEqualsProductAndIsSymmetric) {
  const lat::Lattice l = small_lattice(mess::model_profile("seed"), {5, 5, 5}, {{2, 2, 2}});
  const mess::SpringKernel springs(l);
  const mess::VolumeKernel volume(l);
  const Eigen::Index n = 3 * l.node_count();
  for (const Eigen::Matrix3Xd& x : states(l)) {
    std::vector<Eigen::Triplet<double>> entries;
    mess::SpringKernel::add_hessian_entries(l, x, entries);
    mess::VolumeKernel::add_hessian_entries(l, x, 4.0, entries);
    Eigen::SparseMatrix<double> h(n, n);
    h.setFromTriplets(entries.begin(), entries.end());
    const Eigen::SparseMatrix<double> transposed = h.transpose();
    const Eigen::SparseMatrix<double> asymmetry = h - transposed;
    EXPECT_LT(asymmetry.coeffs().cwiseAbs().maxCoeff(), 1e-12 * h.coeffs().cwiseAbs().maxCoeff());
    for (const std::uint32_t seed : {21U, 22U, 23U}) {
      const Eigen::Matrix3Xd v = random_direction(l.node_count(), seed);
      Eigen::Matrix3Xd hv = Eigen::Matrix3Xd::Zero(3, l.node_count());
      springs.add_hessian_product(l, x, v, hv);
      volume.add_hessian_product(l, x, 4.0, v, hv);
      const Eigen::VectorXd assembled = h * Eigen::Map<const Eigen::VectorXd>(v.data(), n);
      const Eigen::Map<const Eigen::VectorXd> product(hv.data(), n);
      EXPECT_LT((assembled - product).cwiseAbs().maxCoeff(), 1e-12 * product.cwiseAbs().maxCoeff());
    }
  }
}

TEST(MessElasticHessian, ProductsIndependentOfThreadCount) {
  // Large enough for the parallel branches (kParallelMinimum).
  const lat::Lattice l = small_lattice(mess::model_profile("physical"), {30, 30, 24});
  const mess::SpringKernel springs(l);
  const mess::VolumeKernel volume(l);
  const Eigen::Matrix3Xd x = perturbed(l.positions, 0.03 * l.element_length, 9);
  const Eigen::Matrix3Xd v = random_direction(l.node_count(), 31);
  const auto product = [&] {
    Eigen::Matrix3Xd hv = Eigen::Matrix3Xd::Zero(3, l.node_count());
    springs.add_hessian_product(l, x, v, hv);
    volume.add_hessian_product(l, x, 4.0, v, hv);
    return hv;
  };
  const int saved = omp_get_max_threads();
  omp_set_num_threads(1);
  const Eigen::Matrix3Xd one = product();
  omp_set_num_threads(3);
  const Eigen::Matrix3Xd three = product();
  omp_set_num_threads(saved);
  EXPECT_EQ(std::memcmp(one.data(), three.data(), sizeof(double) * one.size()), 0);
}

namespace {

// Records every block it is given, in order; with `nodes` set it says it keeps only the blocks
// between those nodes (HessianBlockSink::takes_node) and drops the others.
class RecordingSink final : public mess::HessianBlockSink {
 public:
  struct Block {
    std::int64_t i;
    std::int64_t j;
    Eigen::Matrix3d b;
  };
  explicit RecordingSink(std::vector<char> nodes = {}) : nodes_(std::move(nodes)) {}
  void add(std::int64_t i, std::int64_t j, const Eigen::Matrix3d& block) override {
    if (filters_nodes() && !(takes_node(i) && takes_node(j))) return;
    blocks.push_back({i, j, block});
  }
  [[nodiscard]] bool filters_nodes() const override { return !nodes_.empty(); }
  [[nodiscard]] bool takes_node(std::int64_t n) const override {
    return nodes_.empty() || nodes_[static_cast<std::size_t>(n)] != 0;
  }
  std::vector<Block> blocks;

 private:
  std::vector<char> nodes_;
};

}  // namespace

// A sink that keeps only some nodes' blocks lets the kernels skip the springs and cells without
// such a node (the contact gaps' blocks): it must still get exactly the blocks between its nodes
// that the whole sweep delivers, bit for bit and in the same order, so that its sums do not
// change.
TEST(MessElasticHessian, FilteringSinkGetsTheWholeSweepsBlocksBetweenItsNodes) {
  const lat::Lattice l = small_lattice(mess::model_profile("seed"), {6, 6, 7}, {{3, 3, 3}});
  std::vector<char> nodes(static_cast<std::size_t>(l.node_count()), 0);
  // A corner region of 2 x 3 x 2 nodes and a lone node: terms with one, some or all nodes in it.
  for (int ix = 0; ix < 2; ++ix) {
    for (int iy = 1; iy < 4; ++iy) {
      for (int iz = 2; iz < 4; ++iz)
        nodes[static_cast<std::size_t>(l.shape.node_index(ix, iy, iz))] = 1;
    }
  }
  nodes[static_cast<std::size_t>(l.shape.node_index(4, 4, 5))] = 1;
  for (const Eigen::Matrix3Xd& x : states(l)) {
    RecordingSink whole;
    RecordingSink filtered(nodes);
    mess::SpringKernel::add_hessian_blocks(l, x, whole);
    mess::VolumeKernel::add_hessian_blocks(l, x, 4.0, whole);
    mess::SpringKernel::add_hessian_blocks(l, x, filtered);
    mess::VolumeKernel::add_hessian_blocks(l, x, 4.0, filtered);
    std::vector<RecordingSink::Block> expected;
    for (const RecordingSink::Block& b : whole.blocks) {
      if (nodes[static_cast<std::size_t>(b.i)] != 0 && nodes[static_cast<std::size_t>(b.j)] != 0) {
        expected.push_back(b);
      }
    }
    ASSERT_GT(expected.size(), 100U);
    ASSERT_EQ(filtered.blocks.size(), expected.size());
    for (std::size_t k = 0; k < expected.size(); ++k) {
      EXPECT_EQ(filtered.blocks[k].i, expected[k].i) << k;
      EXPECT_EQ(filtered.blocks[k].j, expected[k].j) << k;
      EXPECT_EQ(std::memcmp(filtered.blocks[k].b.data(), expected[k].b.data(), 9 * sizeof(double)),
                0)
          << k;
    }
  }
}

TEST(MessWcaHessian, PairProductMatchesDifferencesOfTheGradient) {
  mm::MagneticModel model;
  model.wca = mm::WcaParameters::from_radius(1.5e-6, 1.6e6);
  // Three centres, two pairs inside the cut-off (near contact), one beyond it.
  Eigen::Matrix3Xd c(3, 3);
  c.col(0) = Eigen::Vector3d(0.0, 0.0, 0.0);
  c.col(1) = Eigen::Vector3d(3.02e-6, 0.01e-6, 0.02e-6);
  c.col(2) = Eigen::Vector3d(1.0e-6, 2.85e-6, -0.3e-6);
  const lat::Lattice l = small_lattice(mess::model_profile("physical"), {2, 2, 2});
  const Eigen::Matrix3Xd M = Eigen::Matrix3Xd::Zero(3, 3);
  const Eigen::Matrix3Xd none(3, 0);
  const mess::MessSettings settings;
  const mm::PairList pairs = mm::OpenBoundary{}.pairs(c);
  const mess::TermState state{l, l.positions, c, M, model, none, settings, pairs};
  const mess::TermContext context{l, model, settings};
  std::unique_ptr<mess::EnergyTerm> wca = mess::find_energy_term("wca")->make(context, {});
  ASSERT_EQ(wca->hessian_kind(), mess::HessianKind::exact);
  mess::TermGradient v{Eigen::Matrix3Xd::Zero(3, l.node_count()), random_direction(3, 41)};
  mess::TermGradient hv = mess::TermGradient::zero(state);
  wca->add_hessian_product(state, v, hv);
  const double h = 1e-11;  // m: 1e-4 of the 100 nm gap
  const Eigen::Matrix3Xd fd =
      (mm::wca_gradient(model, c + h * v.centres) - mm::wca_gradient(model, c - h * v.centres)) /
      (2.0 * h);
  EXPECT_GT(fd.cwiseAbs().maxCoeff(), 0.0);
  EXPECT_LT(relative_max_error(hv.centres, fd), 1e-6);
}
