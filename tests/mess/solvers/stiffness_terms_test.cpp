// The preconditioners' stiffness terms over a band of lattice layers
// (solvers/stiffness_terms.hpp, for_each_stiffness_term_in_layers): the multilevel build splits
// each level's points over the threads along z and sweeps, per thread, only the terms whose
// nodes reach its layers. The band must hold every such term, each with the same values as the
// sweep over the whole lattice, and in the whole sweep's order (each level point's sum takes its
// terms in that order, so that the threads give the bits of one thread).

#include "mresim/mess/solvers/stiffness_terms.hpp"

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <tuple>
#include <vector>

#include "../support/mess_test_support.hpp"

namespace mess = mresim::mess;
namespace lat = mresim::lattice;
using mess::testing::faces_held;
using mess::testing::perturbed;
using mess::testing::small_lattice;

namespace {

// One visited term: spring (0, i, j) or cell (1, its first node, its last), its factor c and
// its first direction component (enough to tell values apart).
using VisitedTerm = std::tuple<int, std::int64_t, std::int64_t, double, double>;

std::vector<VisitedTerm> visit_layers(const lat::Lattice& l, const Eigen::Matrix3Xd& x,
                                      const mess::DofMap& map, int z_first, int z_last) {
  std::vector<VisitedTerm> terms;
  mess::for_each_stiffness_term_in_layers(
      l, &x, map, 1.0, 1.0, z_first, z_last,
      [&](std::int64_t i, std::int64_t j, const Eigen::Vector3d& u, double c) {
        terms.emplace_back(0, i, j, c, u.x());
      },
      [&](const auto& element, const lat::CellVertices& g, double c) {
        terms.emplace_back(1, element[0], element[7], c, g[0].x());
      });
  return terms;
}

}  // namespace

TEST(StiffnessTerms, ABandOfLayersHoldsEveryTermThatReachesItInTheWholeSweepsOrder) {
  const mess::ModelProfile& profile = mess::model_profile("physical");
  mess::MessSystem sys = mess::MessSystem::make(small_lattice(profile, {5, 6, 12}, {{2, 3, 6}}),
                                                Eigen::Vector3d::Zero(), profile);
  const lat::Lattice& l = sys.lattice();
  sys.set_constraints(faces_held(l, {lat::Face::bottom}));
  const mess::DofMap map(sys.constraints(), l.positions, l.element_length);
  const Eigen::Matrix3Xd x = perturbed(l.positions, 0.1 * l.element_length, 3);
  const int nz = l.shape.nodes[2];
  const std::vector<VisitedTerm> whole = visit_layers(l, x, map, 0, nz - 1);
  ASSERT_EQ(whole.size(), l.springs.size() + l.elements.size());
  const auto layer_of = [&](std::int64_t n) { return static_cast<int>(n % nz); };
  for (const auto& [z_first, z_last] : std::vector<std::array<int, 2>>{
           {0, 0}, {0, 4}, {3, 3}, {5, 9}, {8, nz - 1}, {nz - 1, nz - 1}}) {
    const std::vector<VisitedTerm> band = visit_layers(l, x, map, z_first, z_last);
    // A subsequence of the whole sweep: the same terms with the same values, in its order.
    std::size_t next = 0;  // where the whole sweep is searched from
    for (const VisitedTerm& t : band) {
      const auto at = std::find(whole.begin() + static_cast<std::ptrdiff_t>(next), whole.end(), t);
      ASSERT_NE(at, whole.end()) << "a term of the band " << z_first << ".." << z_last
                                 << " is not where the whole sweep has it";
      next = static_cast<std::size_t>(at - whole.begin()) + 1;
    }
    // Every term with a node in the band is in it.
    std::size_t reaching = 0;
    for (const VisitedTerm& t : whole) {
      const auto& [kind, first, last, c, value] = t;
      const int low = std::min(layer_of(first), layer_of(last));
      const int high = std::max(layer_of(first), layer_of(last));
      if (high < z_first || low > z_last) continue;
      ++reaching;
      EXPECT_NE(std::find(band.begin(), band.end(), t), band.end())
          << (kind == 0 ? "spring " : "cell ") << first << "-" << last << " not in the band "
          << z_first << ".." << z_last;
    }
    EXPECT_GE(band.size(), reaching);
    // And the band is a band: it leaves out the terms far from it.
    if (z_last - z_first < nz - 4) EXPECT_LT(band.size(), whole.size());
  }
}
