// Tests of the grid stencils (grid_stencil.hpp): their gathers visit every node's springs and
// cells in increasing index, the order of explicit node -> spring/cell lists, on boxes from one
// cell (where two spring offsets share an index step) up; the spring kernel's gradient and
// Hessian product are bitwise those of a gather over such lists, also on a box big enough for
// the parallel loop and with more threads than energy blocks, and its energy with a gradient is
// bitwise the energy-only sum; the same for the volume kernel against a gather of all cells'
// coefficients; and the spring stencil refuses a spring set numbered otherwise.

#include "mresim/mess/terms/grid_stencil.hpp"

#include <gtest/gtest.h>
#include <omp.h>

#include <array>
#include <cstdint>
#include <stdexcept>
#include <utility>
#include <vector>

#include "../support/mess_test_support.hpp"
#include "mresim/mess/terms/elastic_formulas.hpp"
#include "mresim/mess/terms/elastic_terms.hpp"

namespace mess = mresim::mess;
namespace lat = mresim::lattice;
using mess::testing::perturbed;
using mess::testing::small_lattice;

namespace {

// node -> its springs in increasing index (the order the stencil must reproduce).
std::vector<std::vector<std::size_t>> incident_springs(const lat::Lattice& l) {
  std::vector<std::vector<std::size_t>> lists(static_cast<std::size_t>(l.node_count()));
  for (std::size_t s = 0; s < l.springs.size(); ++s) {
    lists[static_cast<std::size_t>(l.springs.first[s])].push_back(s);
    lists[static_cast<std::size_t>(l.springs.second(s))].push_back(s);
  }
  return lists;
}

// Per-node sum of +w(s) (node is the spring's second end) or -w(s) (first end), in the
// lists' order, added to `out` as the kernels do.
template <class W>
void reference_gather(const lat::Lattice& l, Eigen::Matrix3Xd& out, W&& w) {
  const auto lists = incident_springs(l);
  for (Eigen::Index n = 0; n < out.cols(); ++n) {
    Eigen::Vector3d g = out.col(n);
    for (const std::size_t s : lists[static_cast<std::size_t>(n)]) {
      if (l.springs.second(s) == n) {
        g += w(s);
      } else {
        g -= w(s);
      }
    }
    out.col(n) = g;
  }
}

// The spring kernel's gradient and Hessian product against the reference gathers, bitwise.
void expect_kernel_matches_reference(const lat::Lattice& l) {
  const Eigen::Matrix3Xd x = perturbed(l.positions, 0.1 * l.element_length, 5);
  const Eigen::Matrix3Xd v = perturbed(Eigen::Matrix3Xd::Zero(3, x.cols()), 1.0, 6);
  const Eigen::Matrix3Xd start = perturbed(Eigen::Matrix3Xd::Zero(3, x.cols()), 1e-3, 8);
  const lat::SpringSet& sp = l.springs;
  const mess::SpringKernel kernel(l);

  Eigen::Matrix3Xd gradient = start;
  const mess::ElasticValue with_gradient = kernel.evaluate(l, x, &gradient);
  // The fused sweep sums the energy in the blocks of the energy-only evaluation.
  const mess::ElasticValue energy_only = kernel.evaluate(l, x, nullptr);
  EXPECT_EQ(with_gradient.energy, energy_only.energy);
  EXPECT_EQ(with_gradient.rounding, energy_only.rounding);
  Eigen::Matrix3Xd expected = start;
  reference_gather(l, expected, [&](std::size_t s) {
    const Eigen::Vector3d r = x.col(sp.second(s)) - x.col(sp.first[s]);
    const double length = r.norm();
    const double tension = sp.stiffness(s) * (length - sp.rest_length(s)) / length;
    return Eigen::Vector3d(tension * r);
  });
  EXPECT_TRUE(gradient == expected)
      << "largest difference " << (gradient - expected).cwiseAbs().maxCoeff();

  Eigen::Matrix3Xd product = start;
  kernel.add_hessian_product(l, x, v, product);
  Eigen::Matrix3Xd expected_product = start;
  reference_gather(l, expected_product, [&](std::size_t s) {
    // The kernel's B (v_j - v_i) = k [(1 - L/l) dv + (L/l) u (u . dv)], term by term.
    const Eigen::Vector3d r = x.col(sp.second(s)) - x.col(sp.first[s]);
    const double length = r.norm();
    const double ratio = sp.rest_length(s) / length;
    const Eigen::Vector3d u = r / length;
    const Eigen::Vector3d dv = v.col(sp.second(s)) - v.col(sp.first[s]);
    return Eigen::Vector3d(sp.stiffness(s) * ((1.0 - ratio) * dv + (ratio * u.dot(dv)) * u));
  });
  EXPECT_TRUE(product == expected_product)
      << "largest difference " << (product - expected_product).cwiseAbs().maxCoeff();
}

// The volume kernel's gradient against a pass over all cells into an array and the stencil's
// gather (what the kernel did before its layer buffers), and its energy against the energy-only
// sum, bitwise.
void expect_volume_kernel_matches_reference(const lat::Lattice& l, double force_factor) {
  const Eigen::Matrix3Xd x = perturbed(l.positions, 0.1 * l.element_length, 5);
  const Eigen::Matrix3Xd start = perturbed(Eigen::Matrix3Xd::Zero(3, x.cols()), 1e-3, 8);
  const mess::VolumeKernel kernel(l);
  Eigen::Matrix3Xd gradient = start;
  const mess::ElasticValue with_gradient = kernel.evaluate(l, x, force_factor, &gradient);
  const mess::ElasticValue energy_only = kernel.evaluate(l, x, force_factor, nullptr);
  EXPECT_EQ(with_gradient.energy, energy_only.energy);
  EXPECT_EQ(with_gradient.rounding, energy_only.rounding);

  const double v0 = l.element_length * l.element_length * l.element_length;
  std::vector<double> terms(9 * l.elements.size());
  for (std::size_t c = 0; c < l.elements.size(); ++c) {
    lat::CellVertices vertices;
    for (int k = 0; k < 8; ++k) vertices[k] = x.col(l.elements[c][static_cast<std::size_t>(k)]);
    (void)mess::elastic::cell_value(vertices, l.polymer.kappa, v0, force_factor,
                                    terms.data() + 9 * c);
  }
  Eigen::Matrix3Xd expected = start;
  mess::CellStencil(l.shape).gather(expected, [&](std::int64_t cell, int v) {
    return mess::elastic::vertex_gradient(terms.data() + 9 * cell, v);
  });
  EXPECT_TRUE(gradient == expected)
      << "largest difference " << (gradient - expected).cwiseAbs().maxCoeff();
}

// Boxes of one cell, thin along each axis, and cubic.
const std::array<std::array<int, 3>, 5> kSmallBoxes = {
    {{1, 1, 1}, {1, 3, 2}, {4, 1, 5}, {3, 4, 1}, {2, 2, 2}}};

}  // namespace

TEST(GridStencil, GathersVisitSpringsAndCellsInIndexOrder) {
  const int saved = omp_get_max_threads();
  omp_set_num_threads(1);  // the visits are recorded in one sequence, node after node
  for (const std::array<int, 3> cells : kSmallBoxes) {
    SCOPED_TRACE(::testing::Message() << cells[0] << " x " << cells[1] << " x " << cells[2]);
    const lat::Lattice l = small_lattice(mess::model_profile("physical"), cells);
    Eigen::Matrix3Xd out = Eigen::Matrix3Xd::Zero(3, l.node_count());

    // Springs: (spring, first end, second end) per visit.
    std::vector<std::array<std::int64_t, 3>> visited;
    mess::SpringStencil(l).gather(out,
                                  [&](std::int64_t s, std::int64_t first, std::int64_t second) {
                                    visited.push_back({s, first, second});
                                    return Eigen::Vector3d::Zero().eval();
                                  });
    std::vector<std::array<std::int64_t, 3>> expected;
    for (const auto& springs : incident_springs(l)) {
      for (const std::size_t s : springs) {
        expected.push_back({static_cast<std::int64_t>(s), l.springs.first[s], l.springs.second(s)});
      }
    }
    EXPECT_EQ(visited, expected);

    // Cells: (cell, local vertex) per visit; the vertex must be the node's place in the cell.
    std::vector<std::array<std::int64_t, 2>> cells_visited;
    mess::CellStencil(l.shape).gather(out, [&](std::int64_t c, int v) {
      cells_visited.push_back({c, v});
      return Eigen::Vector3d::Zero().eval();
    });
    std::vector<std::array<std::int64_t, 2>> cells_expected;
    for (std::int64_t n = 0; n < l.node_count(); ++n) {
      for (std::size_t c = 0; c < l.elements.size(); ++c) {
        for (int v = 0; v < 8; ++v) {
          if (l.elements[c][static_cast<std::size_t>(v)] == n) {
            cells_expected.push_back({static_cast<std::int64_t>(c), v});
          }
        }
      }
    }
    EXPECT_EQ(cells_visited, cells_expected);
  }
  omp_set_num_threads(saved);
}

TEST(SpringStencil, GatherVisitsEachNodesSpringsInIndexOrderOnSmallBoxes) {
  const mess::ModelProfile physical = mess::model_profile("physical");
  // One cell (2 x 2 x 2 nodes: the offsets (0,0,1) and (1,0,-1) share an index step), thin
  // boxes along each axis, and a box with a particle (other spring constants).
  for (const std::array<int, 3> cells : kSmallBoxes) {
    SCOPED_TRACE(::testing::Message() << cells[0] << " x " << cells[1] << " x " << cells[2]);
    expect_kernel_matches_reference(small_lattice(physical, cells));
  }
  expect_kernel_matches_reference(small_lattice(physical, {5, 5, 6}, {{2, 2, 2}}));
}

TEST(SpringStencil, GatherMatchesTheReferenceOnEveryThreadCount) {
  // Big enough for the parallel gather (detail::kParallelMinimum / 4 nodes).
  const lat::Lattice l =
      small_lattice(mess::model_profile("seed"), {16, 16, 24}, {{8, 8, 6}, {8, 8, 16}});
  ASSERT_GT(l.node_count(), mess::detail::kParallelMinimum / 4);
  const int saved = omp_get_max_threads();
  for (const int threads : {1, 2, 3}) {
    SCOPED_TRACE(threads);
    omp_set_num_threads(threads);
    expect_kernel_matches_reference(l);
  }
  omp_set_num_threads(saved);
}

TEST(SpringKernel, GradientMatchesTheReferenceWithMoreThreadsThanEnergyBlocks) {
  // Just over detail::kParallelMinimum springs: 5 energy blocks for 8 threads, so some threads
  // own no block and the last one the last node alone.
  const lat::Lattice l = small_lattice(mess::model_profile("physical"), {10, 10, 12});
  const auto springs = static_cast<std::int64_t>(l.springs.size());
  ASSERT_GE(springs, mess::detail::kParallelMinimum);
  ASSERT_LT((springs + mess::detail::kSumBlock - 1) / mess::detail::kSumBlock, 8);
  const int saved = omp_get_max_threads();
  for (const int threads : {1, 4, 8}) {
    SCOPED_TRACE(threads);
    omp_set_num_threads(threads);
    expect_kernel_matches_reference(l);
  }
  omp_set_num_threads(saved);
}

TEST(SpringStencil, RefusesSpringsNumberedOtherwise) {
  lat::Lattice l = small_lattice(mess::model_profile("physical"), {2, 2, 2});
  EXPECT_NO_THROW(mess::SpringStencil{l});
  lat::Lattice moved = l;  // spring 3 starts at another node than the stencil's numbering says
  moved.springs.first[3] += 1;
  EXPECT_THROW(mess::SpringStencil{moved}, std::invalid_argument);
  lat::Lattice missing = l;
  missing.springs.first.pop_back();
  EXPECT_THROW(mess::SpringStencil{missing}, std::invalid_argument);
}

TEST(VolumeKernel, GradientMatchesTheReferenceOnSmallBoxes) {
  const mess::ModelProfile physical = mess::model_profile("physical");
  for (const std::array<int, 3> cells : kSmallBoxes) {
    SCOPED_TRACE(::testing::Message() << cells[0] << " x " << cells[1] << " x " << cells[2]);
    expect_volume_kernel_matches_reference(small_lattice(physical, cells), 1.0);
  }
  expect_volume_kernel_matches_reference(small_lattice(physical, {5, 5, 6}, {{2, 2, 2}}), 4.0);
}

TEST(VolumeKernel, GradientMatchesTheReferenceOnEveryThreadCount) {
  // The kernel splits the node planes of constant y over the threads, and each cell's energy
  // comes from the thread of its layer. Layers of 384 cells (many layers per energy block, which
  // runs along x and y), of 350 cells over 61 planes, and of 9,600 cells over 3 planes (with 3
  // and 8 threads some threads own no plane, or only the top one, which starts no layer).
  const mess::ModelProfile seed = mess::model_profile("seed");
  const lat::Lattice thin_layers = small_lattice(seed, {16, 16, 24}, {{8, 8, 6}, {8, 8, 16}});
  const lat::Lattice wide_layers = small_lattice(seed, {70, 60, 5});
  const lat::Lattice few_planes = small_lattice(seed, {160, 2, 60});
  ASSERT_GE(static_cast<std::int64_t>(wide_layers.elements.size()), mess::detail::kParallelMinimum);
  ASSERT_GE(static_cast<std::int64_t>(few_planes.elements.size()), mess::detail::kParallelMinimum);
  const int saved = omp_get_max_threads();
  for (const int threads : {1, 2, 3, 8}) {
    SCOPED_TRACE(threads);
    omp_set_num_threads(threads);
    expect_volume_kernel_matches_reference(thin_layers, 4.0);
    expect_volume_kernel_matches_reference(wide_layers, 1.0);
    expect_volume_kernel_matches_reference(few_planes, 1.0);
  }
  omp_set_num_threads(saved);
}
