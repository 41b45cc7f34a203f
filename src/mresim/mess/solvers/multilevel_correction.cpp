#include "mresim/mess/solvers/multilevel_correction.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <exception>
#include <stdexcept>
#include <string>
#include <utility>

#include "mresim/mess/solvers/stiffness_terms.hpp"

namespace mresim::mess {

namespace {

// Grid fields of 3-vectors are stored node by node, node index iz + nz (ix + nx iy), as the
// lattice numbers its nodes (lattice/grid.hpp). dims = {nx, ny, nz}.
using Dims = std::array<int, 3>;

std::int64_t point_count(const Dims& d) { return static_cast<std::int64_t>(d[0]) * d[1] * d[2]; }

// A grid field of 3-vectors seen along one axis: `outer` blocks, each of the axis's points in
// turn, each point a slice of `inner` contiguous values (the node numbering iz + nz (ix + nx iy)
// makes z the fastest axis, then x, then y). Along z a slice is one node's 3 values; along x it
// is a whole z-line of the grid (3 nz values), along y a whole y-plane (3 nz nx).
struct AxisView {
  std::int64_t outer = 0;
  std::int64_t inner = 0;
};

AxisView view_along(const Dims& d, int axis) {
  if (axis == 2) return {static_cast<std::int64_t>(d[0]) * d[1], 3};
  if (axis == 0) return {d[1], 3 * static_cast<std::int64_t>(d[2])};
  return {1, 3 * static_cast<std::int64_t>(d[2]) * d[0]};
}

// Runs slice(o, j) for the slices j < points of every block o < outer of an output whose
// slices hold `inner` values, in parallel when there is enough work; each slice is one
// thread's, so what it computes does not depend on the number of threads.
template <class Slice>
void for_each_slice(std::int64_t outer, int points, std::int64_t inner, Slice&& slice) {
#pragma omp parallel for collapse(2) schedule(static) if (outer * points * inner > 60000)
  for (std::int64_t o = 0; o < outer; ++o) {
    for (int j = 0; j < points; ++j) slice(o, j);
  }
}

// Restricts a field of 3-vectors on the grid `dims` along `axis` to `level`'s points there:
// out[j] = sum_i phi_j(i) in[i] over each grid line, the terms in increasing i (Axis::term_begin).
// Whole slices at a time, so the inner loops run over contiguous values. read(c) gives the
// input at flat index c = 3 node + component.
template <class Axis, class Read>
void restrict_axis(Read&& read, const Dims& dims, int axis, const Axis& ax, int n_out,
                   Eigen::VectorXd& out) {
  const AxisView view = view_along(dims, axis);
  const std::int64_t n_in = dims[static_cast<std::size_t>(axis)];
  out.resize(view.outer * n_out * view.inner);
  double* const result = out.data();
  for_each_slice(view.outer, n_out, view.inner, [&](std::int64_t o, int point) {
    const auto j = static_cast<std::size_t>(point);
    double* const dst = result + (o * n_out + point) * view.inner;
    const int first = ax.term_begin[j];
    const int last = ax.term_begin[j + 1];
    // Each value's sum in a register, its terms in increasing i (starting from 0.0, as a sweep
    // that adds into a zeroed array would): the values of a slice are independent sums.
    if (view.inner == 3) {  // along z: one node's three values, the terms read once for all
      std::array<double, 3> sum{0.0, 0.0, 0.0};
      for (int t = first; t < last; ++t) {
        const auto term = static_cast<std::size_t>(t);
        const double w = ax.term_weight[term];
        const std::int64_t src = (o * n_in + ax.term_fine[term]) * 3;
        for (std::size_t e = 0; e < 3; ++e) sum[e] += w * read(src + static_cast<std::int64_t>(e));
      }
      for (std::size_t e = 0; e < 3; ++e) dst[e] = sum[e];
      return;
    }
    for (std::int64_t e = 0; e < view.inner; ++e) {
      double sum = 0.0;
      for (int t = first; t < last; ++t) {
        const auto term = static_cast<std::size_t>(t);
        sum += ax.term_weight[term] * read((o * n_in + ax.term_fine[term]) * view.inner + e);
      }
      dst[e] = sum;
    }
  });
}

// The transpose: interpolates `in` (on `coarse` dims, `level`'s points along `axis`) to the
// `n_fine` points of the finer grid along `axis`; write(c, value) takes each fine value once,
// c the flat index on the finer grid.
template <class Axis, class Write>
void interpolate_axis(const Eigen::VectorXd& in, const Dims& coarse, int axis, const Axis& ax,
                      int n_fine, Write&& write) {
  const AxisView view = view_along(coarse, axis);
  const std::int64_t n_coarse = coarse[static_cast<std::size_t>(axis)];
  const double* const source = in.data();
  for_each_slice(view.outer, n_fine, view.inner, [&](std::int64_t o, int point) {
    const auto i = static_cast<std::size_t>(point);
    const double t = ax.upper[i];
    const double* const a = source + (o * n_coarse + ax.lower[i]) * view.inner;
    const double* const b = a + view.inner;
    const std::int64_t base = (o * n_fine + point) * view.inner;
    if (t == 0.0) {
      for (std::int64_t e = 0; e < view.inner; ++e) write(base + e, a[e]);
    } else {
      for (std::int64_t e = 0; e < view.inner; ++e) write(base + e, (1.0 - t) * a[e] + t * b[e]);
    }
  });
}

auto vector_reader(const Eigen::VectorXd& v) {
  const double* const data = v.data();
  return [data](std::int64_t c) { return data[c]; };
}

// Writes into `v`, sized for the grid `dims`.
auto vector_writer(Eigen::VectorXd& v, const Dims& dims) {
  v.resize(3 * point_count(dims));
  double* const data = v.data();
  return [data](std::int64_t c, double value) { data[c] = value; };
}

constexpr int kReach = 2;  // the coarsest level's couplings reach 2 points along each axis
constexpr int kWidth = 2 * kReach + 1;
constexpr int kNeighbours = kWidth * kWidth * kWidth;

}  // namespace

MultilevelCorrection::MultilevelCorrection(const lattice::Lattice& lattice,
                                           double volume_force_factor, const DofMap& map,
                                           double force_scale, const Eigen::Matrix3Xd* state,
                                           Eigen::Index exact_limit,
                                           const detail::BlockSplit* processes) {
  fine_ = lattice.shape.nodes;
  own_dofs_ = map.own_dofs();
  levels_ = build_levels(fine_, exact_limit);
  assemble(lattice, volume_force_factor, lattice.element_length / force_scale, map, state,
           processes);
}

Eigen::Index MultilevelCorrection::level_size(int level) const {
  const Level& l = levels_.at(static_cast<std::size_t>(level - 1));
  return 3 * point_count(l.points);
}

void MultilevelCorrection::add_restriction_terms(Axis& axis, int points) {
  // Point i of the finer grid gives (1 - t_i) to its lower bracket and t_i to the upper one
  // (when t_i != 0); each coarse point takes its terms in increasing i.
  std::vector<std::vector<std::pair<int, double>>> terms(static_cast<std::size_t>(points));
  for (std::size_t i = 0; i < axis.lower.size(); ++i) {
    const auto lower = static_cast<std::size_t>(axis.lower[i]);
    const double t = axis.upper[i];
    terms[lower].emplace_back(static_cast<int>(i), 1.0 - t);
    if (t != 0.0) terms[lower + 1].emplace_back(static_cast<int>(i), t);
  }
  axis.term_begin.assign(1, 0);
  for (const auto& point : terms) {
    for (const auto& [fine, weight] : point) {
      axis.term_fine.push_back(fine);
      axis.term_weight.push_back(weight);
    }
    axis.term_begin.push_back(static_cast<int>(axis.term_fine.size()));
  }
}

std::vector<std::array<int, 3>> MultilevelCorrection::level_points(const std::array<int, 3>& nodes,
                                                                   Eigen::Index exact_limit) {
  std::vector<std::array<int, 3>> points;
  for (const Level& level : build_levels(nodes, exact_limit)) points.push_back(level.points);
  return points;
}

std::vector<MultilevelCorrection::Level> MultilevelCorrection::build_levels(
    const std::array<int, 3>& fine, Eigen::Index exact_limit) {
  if (exact_limit < 1) {
    throw std::invalid_argument("MultilevelCorrection: exact_limit " + std::to_string(exact_limit) +
                                " must be at least 1");
  }
  std::vector<Level> levels;
  std::array<std::vector<int>, 3> planes;
  for (std::size_t a = 0; a < 3; ++a) {
    planes[a].resize(static_cast<std::size_t>(fine[a]));
    for (int i = 0; i < fine[a]; ++i) planes[a][static_cast<std::size_t>(i)] = i;
  }
  while (true) {
    Level level;
    bool coarser = false;
    for (std::size_t a = 0; a < 3; ++a) {
      const std::vector<int>& finer = planes[a];
      Axis& axis = level.axes[a];
      for (std::size_t i = 0; i < finer.size(); i += 2) axis.plane.push_back(finer[i]);
      if (axis.plane.back() != finer.back()) axis.plane.push_back(finer.back());
      coarser = coarser || axis.plane.size() < finer.size();
      const auto m = static_cast<int>(axis.plane.size());
      for (std::size_t i = 0; i < finer.size(); ++i) {
        const int lower = std::min(static_cast<int>(i / 2), m - 2);
        const double p0 = axis.plane[static_cast<std::size_t>(lower)];
        const double p1 = axis.plane[static_cast<std::size_t>(lower) + 1];
        axis.lower.push_back(lower);
        axis.upper.push_back((finer[i] - p0) / (p1 - p0));
      }
      add_restriction_terms(axis, m);
      level.points[a] = m;
    }
    // A grid of two planes per axis cannot be coarsened: the previous level is the coarsest.
    if (!coarser && !levels.empty()) break;
    for (std::size_t a = 0; a < 3; ++a) planes[a] = level.axes[a].plane;
    levels.push_back(std::move(level));
    // The coarsest level is solved exactly at every application, so it must also be small
    // against the lattice: at most 1/64 of its coordinates (two coarsenings where possible).
    const std::int64_t size = 3 * point_count(levels.back().points);
    if (size <= exact_limit && 64 * size <= 3 * point_count(fine)) break;
  }
  return levels;
}

namespace {

// The sums of one level: the diagonal of Phi^T A Phi (3 per point), and when the level is solved
// exactly the 3 x 3 blocks of each point with its neighbours (<= kReach apart) that its sparse
// factor reads (the lower triangle), kNeighbours per point.
struct LevelSums {
  std::vector<double> diagonal;
  std::vector<double> blocks;
};

// The lattice nodes of one term (a spring's two, a cell's eight): their grid coordinates (x, y,
// z), which of their coordinates are free, and the lowest and highest layer along z they reach.
struct TermNodes {
  std::array<std::array<int, 3>, 8> grid{};
  std::array<std::array<bool, 3>, 8> free{};
  std::size_t count = 0;
  int z_low = 0;
  int z_high = 0;
};

// Fills TermNodes from node indices, once per term for all levels.
class NodeLocator {
 public:
  NodeLocator(const Dims& fine, const DofMap& map)
      : fine_(fine), map_(map), inverse_nz_(1.0 / fine[2]), inverse_nx_(1.0 / fine[0]) {}

  template <std::size_t Count>
  void locate(const std::array<std::int64_t, Count>& nodes, TermNodes& term) const {
    static_assert(Count <= 8);
    term.count = Count;
    term.z_low = fine_[2];
    term.z_high = -1;
    for (std::size_t k = 0; k < Count; ++k) {
      const auto n = static_cast<std::int32_t>(nodes[k]);  // DofMap: 3 N fits 32 bits
      const std::int32_t line = quotient(n, fine_[2], inverse_nz_);
      const std::int32_t iy = quotient(line, fine_[0], inverse_nx_);
      const int iz = n - line * fine_[2];
      term.grid[k] = {line - iy * fine_[0], iy, iz};
      term.z_low = std::min(term.z_low, iz);
      term.z_high = std::max(term.z_high, iz);
      for (std::size_t a = 0; a < 3; ++a) {
        term.free[k][a] =
            map_.own_dof_of_coordinate(3 * nodes[k] + static_cast<std::int64_t>(a)) >= 0;
      }
    }
  }

 private:
  // n / d for 0 <= n < 2^31 and d > 0 without a division instruction: the quotient of the
  // floating-point product, corrected by one where it rounded across an integer.
  static std::int32_t quotient(std::int32_t n, std::int32_t d, double inverse_d) {
    auto q = static_cast<std::int32_t>(static_cast<double>(n) * inverse_d);
    if (q * d > n) --q;
    if ((q + 1) * d <= n) ++q;
    return q;
  }
  Dims fine_;
  const DofMap& map_;
  double inverse_nz_;
  double inverse_nx_;
};

// Adds the rank-one terms c z z^T of the stiffness (stiffness_terms.hpp) projected onto one level
// into the sums of the level points it owns: those whose index along z lies in [owned_first,
// owned_end). Each owned sum takes every term in the order the terms come, so the threads that
// split a level's points between them give each sum the bits one thread would.
class LevelAssembler {
 public:
  LevelAssembler(const std::array<std::vector<int>, 3>& planes, const Dims& fine,
                 const Dims& points, LevelSums& sums, int owned_first, int owned_end)
      : points_(points), sums_(sums), owned_first_(owned_first), owned_end_(owned_end) {
    // Each lattice plane's bracket on this level: the composition of the levels' linear
    // interpolations is the linear interpolation in lattice coordinates (nested grids).
    for (std::size_t a = 0; a < 3; ++a) {
      const std::vector<int>& plane = planes[a];
      std::size_t j = 0;
      for (int f = 0; f < fine[a]; ++f) {
        while (j + 2 < plane.size() && plane[j + 1] <= f) ++j;
        const double t = static_cast<double>(f - plane[j]) / (plane[j + 1] - plane[j]);
        lower_[a].push_back(static_cast<int>(j));
        upper_[a].push_back(t);
        lower_weight_[a].push_back(1.0 - t);
      }
    }
  }

  // Starts a term over the lattice nodes `term` (then add_node(k, ...) for each k-th of them):
  // its projection lives on the level points that bracket them, a patch of at most 3 along each
  // axis (springs and cells join lattice points at most one plane apart, and each coarser
  // plane's bracket moves by at most one point from one lattice plane to the next).
  void start(const TermNodes& term) {
    term_ = &term;
    touched_count_ = 0;
    touched_mask_ = 0;
    base_ = {points_[0], points_[1], points_[2]};
    for (std::size_t k = 0; k < term.count; ++k) {
      for (std::size_t a = 0; a < 3; ++a) {
        base_[a] = std::min(base_[a], lower_[a][static_cast<std::size_t>(term.grid[k][a])]);
      }
    }
  }

  // z += sign direction_a phi_n for the free coordinates a of the k-th node n of start(). A
  // point's value is the sum of its nodes' parts in the order they come (as a list of entries
  // merged by point would give it); each part's weight is sign times the x, y and z factors of
  // the trilinear interpolation, multiplied in that order, and points of weight 0 are skipped.
  void add_node(std::size_t k, const Eigen::Vector3d& direction, double sign) {
    const std::array<int, 3>& i = term_->grid[k];
    const std::array<bool, 3>& free = term_->free[k];
    // Per axis the patch offsets with a nonzero factor and their factors.
    std::array<std::array<int, 2>, 3> offset{};
    std::array<std::array<double, 2>, 3> factor{};
    std::array<int, 3> count{};
    for (std::size_t a = 0; a < 3; ++a) {
      const auto f = static_cast<std::size_t>(i[a]);
      const int low = lower_[a][f] - base_[a];
      if (lower_weight_[a][f] != 0.0) {
        offset[a][static_cast<std::size_t>(count[a])] = low;
        factor[a][static_cast<std::size_t>(count[a]++)] = lower_weight_[a][f];
      }
      if (upper_[a][f] != 0.0) {
        offset[a][static_cast<std::size_t>(count[a])] = low + 1;
        factor[a][static_cast<std::size_t>(count[a]++)] = upper_[a][f];
      }
      if (offset[a][static_cast<std::size_t>(count[a] - 1)] > 2) {
        throw std::logic_error("MultilevelCorrection: a term reaches beyond its 3 x 3 x 3 patch");
      }
    }
    for (std::size_t ex = 0; ex < static_cast<std::size_t>(count[0]); ++ex) {
      const double wx = sign * factor[0][ex];
      for (std::size_t ey = 0; ey < static_cast<std::size_t>(count[1]); ++ey) {
        const double wxy = wx * factor[1][ey];
        for (std::size_t ez = 0; ez < static_cast<std::size_t>(count[2]); ++ez) {
          const double w = wxy * factor[2][ez];
          std::array<double, 3> value{};
          for (std::size_t a = 0; a < 3; ++a) {
            if (free[a]) value[a] = w * direction[static_cast<Eigen::Index>(a)];
          }
          const int p = 9 * offset[0][ex] + 3 * offset[1][ey] + offset[2][ez];
          auto& point = patch_[static_cast<std::size_t>(p)];
          const std::uint32_t bit = 1U << static_cast<unsigned>(p);
          if ((touched_mask_ & bit) == 0) {
            touched_mask_ |= bit;
            touched_[static_cast<std::size_t>(touched_count_++)] = p;
            point = value;
          } else {
            for (std::size_t a = 0; a < 3; ++a) point[a] += value[a];
          }
        }
      }
    }
  }

  // Adds c z z^T to the owned points' sums.
  void add_term(double c) {
    // The level point of each touched patch point, and whether it is this assembler's.
    std::array<std::int64_t, 27> node_of;  // NOLINT(cppcoreguidelines-pro-type-member-init)
    std::array<bool, 27> owned;            // NOLINT(cppcoreguidelines-pro-type-member-init)
    for (int t = 0; t < touched_count_; ++t) {
      const int p = touched_[static_cast<std::size_t>(t)];
      node_of[static_cast<std::size_t>(p)] = point_of(p);
      const int jz = base_[2] + p % 3;
      owned[static_cast<std::size_t>(p)] = jz >= owned_first_ && jz < owned_end_;
    }
    for (int t = 0; t < touched_count_; ++t) {
      const int p = touched_[static_cast<std::size_t>(t)];
      if (!owned[static_cast<std::size_t>(p)]) continue;
      const auto& e = patch_[static_cast<std::size_t>(p)];
      const std::int64_t node = node_of[static_cast<std::size_t>(p)];
      for (std::size_t a = 0; a < 3; ++a) {
        sums_.diagonal[static_cast<std::size_t>(3 * node) + a] += c * e[a] * e[a];
      }
    }
    if (sums_.blocks.empty()) return;
    // Only the blocks the factor reads: its sparse LDL^T takes the lower triangle, so point J
    // needs the blocks of its neighbours K <= J (coordinates are numbered 3 J + a). Patch
    // offsets differ by at most 2 <= kReach along each axis, so the neighbour code of q seen
    // from p is code_of(q) - code_of(p) + code_of(kReach, kReach, kReach).
    constexpr int kCentre = kReach * kWidth * kWidth + kReach * kWidth + kReach;
    std::array<int, 27> code_of;  // NOLINT(cppcoreguidelines-pro-type-member-init)
    for (int t = 0; t < touched_count_; ++t) {
      const int p = touched_[static_cast<std::size_t>(t)];
      code_of[static_cast<std::size_t>(p)] =
          (p / 9) * kWidth * kWidth + ((p / 3) % 3) * kWidth + p % 3;
    }
    for (int t = 0; t < touched_count_; ++t) {
      const int p = touched_[static_cast<std::size_t>(t)];
      if (!owned[static_cast<std::size_t>(p)]) continue;
      const auto& e = patch_[static_cast<std::size_t>(p)];
      // (c e_a) f_b, as c * e_a * f_b evaluates.
      const double ce0 = c * e[0];
      const double ce1 = c * e[1];
      const double ce2 = c * e[2];
      const std::int64_t node = node_of[static_cast<std::size_t>(p)];
      double* const row = sums_.blocks.data() +
                          (node * kNeighbours + kCentre - code_of[static_cast<std::size_t>(p)]) * 9;
      for (int s = 0; s < touched_count_; ++s) {
        const int q = touched_[static_cast<std::size_t>(s)];
        if (node_of[static_cast<std::size_t>(q)] > node) continue;
        const auto& f = patch_[static_cast<std::size_t>(q)];
        double* const block = row + std::ptrdiff_t{code_of[static_cast<std::size_t>(q)]} * 9;
        block[0] += ce0 * f[0];
        block[1] += ce0 * f[1];
        block[2] += ce0 * f[2];
        block[3] += ce1 * f[0];
        block[4] += ce1 * f[1];
        block[5] += ce1 * f[2];
        block[6] += ce2 * f[0];
        block[7] += ce2 * f[1];
        block[8] += ce2 * f[2];
      }
    }
  }

 private:
  // Level point index of patch point p.
  std::int64_t point_of(int p) const {
    const std::int64_t jx = base_[0] + p / 9;
    const std::int64_t jy = base_[1] + (p / 3) % 3;
    const std::int64_t jz = base_[2] + p % 3;
    return jz + points_[2] * (jx + static_cast<std::int64_t>(points_[0]) * jy);
  }

  Dims points_;
  LevelSums& sums_;
  int owned_first_;
  int owned_end_;
  // Per axis and lattice plane: the lower bracketing level point, and the interpolation's
  // factors of the upper (t) and lower (1 - t) one.
  std::array<std::vector<int>, 3> lower_;
  std::array<std::vector<double>, 3> upper_;
  std::array<std::vector<double>, 3> lower_weight_;
  // The current term: its nodes, its patch's lowest point, and its values on the patch (point
  // 9 dx + 3 dy + dz) with the points it touched.
  const TermNodes* term_ = nullptr;
  std::array<int, 3> base_{};
  std::array<std::array<double, 3>, 27> patch_{};
  std::array<int, 27> touched_{};
  int touched_count_ = 0;
  std::uint32_t touched_mask_ = 0;
};

// One level to build: its lattice planes along each axis, its points, whether it is solved
// exactly, and its sums.
struct LevelBuild {
  std::array<std::vector<int>, 3> planes;
  Dims points{};
  bool exact = false;
  LevelSums sums;
};

// The stiffness terms of stiffness_terms.hpp, linearised at `state` (null: at rest), projected
// onto the levels `builds`, all in one sweep of the terms. The threads split each level's
// points along z by the same lattice layers, each sweeping the terms that reach its own points
// (each term computed once for all levels), so the sums do not depend on the number of threads.
void assemble_levels(const lattice::Lattice& lattice, const Eigen::Matrix3Xd* state,
                     const DofMap& map, double volume_force_factor, double scale,
                     std::vector<LevelBuild>& builds) {
  const Dims fine = lattice.shape.nodes;
  for (LevelBuild& build : builds) {
    const std::int64_t count = point_count(build.points);
    build.sums.diagonal.assign(static_cast<std::size_t>(3 * count), 0.0);
    if (build.exact) {
      build.sums.blocks.assign(static_cast<std::size_t>(count * kNeighbours * 9), 0.0);
    }
  }
  std::exception_ptr failure;
#pragma omp parallel if (point_count(fine) >= 20000)
  {
    const int parts = omp_get_num_threads();
    const int part = omp_get_thread_num();
    try {
      // This thread's points on every level: those on the lattice layers [part, part + 1) nz /
      // parts along z (the longest axis of the chapter's boxes, so the terms that two threads
      // both sweep are few); on each level the terms that reach them lie in the layers between
      // the neighbouring points, a band.
      std::vector<LevelAssembler> levels;
      std::vector<std::array<int, 2>> bands;
      int z_first = fine[2];
      int z_last = -1;
      for (LevelBuild& build : builds) {
        const std::vector<int>& z_planes = build.planes[2];
        const auto z_points = static_cast<int>(z_planes.size());
        const auto from_part = [&](int jz, int which) {
          return static_cast<std::int64_t>(z_planes[static_cast<std::size_t>(jz)]) * parts >=
                 static_cast<std::int64_t>(which) * fine[2];
        };
        int first = 0;
        while (first < z_points && !from_part(first, part)) ++first;
        int end = first;
        while (end < z_points && !from_part(end, part + 1)) ++end;
        if (first == end) continue;
        levels.emplace_back(build.planes, fine, build.points, build.sums, first, end);
        const int low = first > 0 ? z_planes[static_cast<std::size_t>(first) - 1] : 0;
        const int high = end < z_points ? z_planes[static_cast<std::size_t>(end)] : fine[2] - 1;
        bands.push_back({low, high});
        z_first = std::min(z_first, low);
        z_last = std::max(z_last, high);
      }
      const NodeLocator locator(fine, map);
      TermNodes term;
      // Each level that the term reaches within its band takes it.
      const auto project = [&](auto&& add_nodes, double c) {
        for (std::size_t l = 0; l < levels.size(); ++l) {
          if (term.z_high < bands[l][0] || term.z_low > bands[l][1]) continue;
          levels[l].start(term);
          add_nodes(levels[l]);
          levels[l].add_term(c);
        }
      };
      if (!levels.empty()) {
        for_each_stiffness_term_in_layers(
            lattice, state, map, volume_force_factor, scale, z_first, z_last,
            [&](std::int64_t i, std::int64_t j, const Eigen::Vector3d& u, double c) {
              locator.locate(std::array<std::int64_t, 2>{j, i}, term);
              project(
                  [&u](LevelAssembler& level) {
                    level.add_node(0, u, 1.0);
                    level.add_node(1, u, -1.0);
                  },
                  c);
            },
            [&](const auto& element, const lattice::CellVertices& g, double c) {
              std::array<std::int64_t, 8> nodes{};
              for (std::size_t v = 0; v < 8; ++v) nodes[v] = element[v];
              locator.locate(nodes, term);
              project(
                  [&g](LevelAssembler& level) {
                    for (std::size_t v = 0; v < 8; ++v) level.add_node(v, g[v], 1.0);
                  },
                  c);
            });
      }
    } catch (...) {
#pragma omp critical(mresim_multilevel_assembly)
      failure = std::current_exception();
    }
  }
  if (failure) std::rethrow_exception(failure);
}

// The process that builds each level when `processes` share the build: the levels in build
// order (the coarsest, about twice the work of another, first), each to the process with the
// least work so far (the lowest rank on a tie). The same on every process.
std::vector<int> level_owners(std::int64_t count, int processes) {
  std::vector<int> owner(static_cast<std::size_t>(count), 0);
  std::vector<int> load(static_cast<std::size_t>(std::max(processes, 1)), 0);
  for (std::int64_t order = 0; order < count; ++order) {
    const std::int64_t li = count - 1 - order;
    const auto least = static_cast<int>(std::min_element(load.begin(), load.end()) - load.begin());
    owner[static_cast<std::size_t>(li)] = least;
    load[static_cast<std::size_t>(least)] += order == 0 ? 2 : 1;
  }
  return owner;
}

}  // namespace

void MultilevelCorrection::assemble(const lattice::Lattice& lattice, double volume_force_factor,
                                    double scale, const DofMap& map, const Eigen::Matrix3Xd* state,
                                    const detail::BlockSplit* processes) {
  // All levels in one sweep of the terms, split over the threads by points (assemble_levels).
  // Over several processes each builds its own levels (level_owners) and shares them.
  std::exception_ptr failure;
  const auto count = static_cast<std::int64_t>(levels_.size());
  const bool shared = processes != nullptr && processes->processes() > 1;
  const std::vector<int> owner = level_owners(count, shared ? processes->processes() : 1);
  const int rank = shared ? processes->rank() : 0;
  std::vector<double> coarsest;  // shared: the coarsest level's diagonal, then its blocks
  std::vector<char> failed(static_cast<std::size_t>(count), 0);
  std::vector<std::int64_t> mine;  // the levels this process builds
  std::vector<LevelBuild> builds;
  for (std::int64_t li = 0; li < count; ++li) {
    if (owner[static_cast<std::size_t>(li)] != rank) continue;
    const Level& level = levels_[static_cast<std::size_t>(li)];
    mine.push_back(li);
    builds.push_back({{level.axes[0].plane, level.axes[1].plane, level.axes[2].plane},
                      level.points,
                      li + 1 == count,
                      {}});
  }
  try {
    assemble_levels(lattice, state, map, volume_force_factor, scale, builds);
  } catch (...) {
    failure = std::current_exception();
    for (const std::int64_t li : mine) failed[static_cast<std::size_t>(li)] = 1;
    builds.clear();
  }
  for (std::size_t b = 0; b < builds.size(); ++b) {
    const std::int64_t li = mine[b];
    try {
      Level& level = levels_[static_cast<std::size_t>(li)];
      const LevelSums& sums = builds[b].sums;
      const std::int64_t points = point_count(level.points);
      if (builds[b].exact) {
        if (shared) {
          coarsest = sums.diagonal;
          coarsest.insert(coarsest.end(), sums.blocks.begin(), sums.blocks.end());
        }
        factor_coarsest(level.points, sums.diagonal, sums.blocks);
        continue;
      }
      level.inverse_diagonal = Eigen::VectorXd::Zero(3 * points);
      for (std::int64_t q = 0; q < 3 * points; ++q) {
        const double d = sums.diagonal[static_cast<std::size_t>(q)];
        if (d > 0.0) level.inverse_diagonal[q] = 1.0 / d;
      }
    } catch (...) {
      failure = std::current_exception();
      failed[static_cast<std::size_t>(li)] = 1;
    }
  }
  if (shared) share_levels(owner, *processes, coarsest, failed);
  if (failure) std::rethrow_exception(failure);
}

void MultilevelCorrection::share_levels(const std::vector<int>& owner,
                                        const detail::BlockSplit& processes,
                                        std::vector<double>& coarsest,
                                        const std::vector<char>& failed) {
  // Each level travels from its owner with one more value at the end: 1 if the owner built
  // it, 0 if its build failed. Every process sees the same flags, so all stop sharing at the
  // first failed level and fail alike (its owner with its own error, in assemble).
  const int rank = processes.rank();
  const std::size_t count = levels_.size();
  for (std::size_t li = 0; li < count; ++li) {
    const bool mine = owner[li] == rank;
    const bool exact = li + 1 == count;
    Level& level = levels_[li];
    std::vector<double> values;
    if (mine) {
      if (exact) {
        values.swap(coarsest);  // the coarsest level is the last one shared
      } else {
        values.assign(level.inverse_diagonal.data(),
                      level.inverse_diagonal.data() + level.inverse_diagonal.size());
      }
      values.push_back(failed[li] != 0 ? 0.0 : 1.0);
    }
    processes.share_from(owner[li], values);
    if (values.empty() || values.back() != 1.0) {
      if (mine) return;  // assemble rethrows the owner's own error
      throw std::runtime_error("MultilevelCorrection: level " + std::to_string(li + 1) +
                               " could not be built on process " + std::to_string(owner[li]) +
                               " (the coarsest level's Hessian is singular if no rigid motion "
                               "of the lattice is held)");
    }
    if (mine) continue;
    values.pop_back();
    const std::int64_t points = point_count(level.points);
    if (!exact) {
      level.inverse_diagonal = Eigen::Map<const Eigen::VectorXd>(values.data(), 3 * points);
      continue;
    }
    const auto diagonal_end = values.begin() + 3 * points;
    factor_coarsest(level.points, std::vector<double>(values.begin(), diagonal_end),
                    std::vector<double>(diagonal_end, values.end()));
  }
}

void MultilevelCorrection::factor_coarsest(const std::array<int, 3>& p,
                                           const std::vector<double>& diagonal,
                                           const std::vector<double>& blocks) {
  const std::int64_t points = point_count(p);
  exact_index_.assign(static_cast<std::size_t>(3 * points), -1);
  Eigen::Index rows = 0;
  for (std::size_t q = 0; q < diagonal.size(); ++q) {
    if (diagonal[q] > 0.0) exact_index_[q] = rows++;
  }
  std::vector<Eigen::Triplet<double>> triplets;
  for (std::int64_t e = 0; e < points; ++e) {
    const std::array<std::int64_t, 3> je{(e / p[2]) % p[0], e / p[2] / p[0], e % p[2]};
    for (int code = 0; code < kNeighbours; ++code) {
      const std::array<std::int64_t, 3> jf{je[0] + code / (kWidth * kWidth) - kReach,
                                           je[1] + (code / kWidth) % kWidth - kReach,
                                           je[2] + code % kWidth - kReach};
      if (jf[0] < 0 || jf[1] < 0 || jf[2] < 0 || jf[0] >= p[0] || jf[1] >= p[1] || jf[2] >= p[2]) {
        continue;
      }
      const std::int64_t f = jf[2] + p[2] * (jf[0] + static_cast<std::int64_t>(p[0]) * jf[1]);
      for (std::int64_t a = 0; a < 3; ++a) {
        const Eigen::Index row = exact_index_[static_cast<std::size_t>(3 * e + a)];
        if (row < 0) continue;
        for (std::int64_t b = 0; b < 3; ++b) {
          const Eigen::Index col = exact_index_[static_cast<std::size_t>(3 * f + b)];
          if (col > row) continue;  // the factor reads the lower triangle only
          const double value =
              blocks[static_cast<std::size_t>((e * kNeighbours + code) * 9 + 3 * a + b)];
          if (col >= 0 && value != 0.0) triplets.emplace_back(row, col, value);
        }
      }
    }
  }
  Eigen::SparseMatrix<double> matrix(rows, rows);
  matrix.setFromTriplets(triplets.begin(), triplets.end());
  factor_.compute(matrix);
  // Nothing held (or a rigid motion left free): A is singular and so is the coarsest matrix.
  const Eigen::VectorXd pivots = factor_.vectorD();
  if (factor_.info() != Eigen::Success || rows == 0 ||
      !(pivots.minCoeff() > 1e-12 * pivots.maxCoeff())) {
    throw std::runtime_error(
        "MultilevelCorrection: the coarsest level's Hessian is singular (no rigid motion of the "
        "lattice is held)");
  }
}

void MultilevelCorrection::add_to(const DofMap& map, const Eigen::VectorXd& v,
                                  Eigen::VectorXd& w) const {
  if (map.own_dofs() != own_dofs_) {
    throw std::invalid_argument("MultilevelCorrection::add_to: the map has " +
                                std::to_string(map.own_dofs()) +
                                " free coordinates, the correction " + std::to_string(own_dofs_));
  }
  // The lattice field is v read through the coordinates' dofs (0 on held coordinates and rigid
  // groups' nodes); the coarse fields are vectors, held only while C is applied.
  const auto read_lattice = [&](std::int64_t coordinate) {
    const Eigen::Index k = map.own_dof_of_coordinate(coordinate);
    return k >= 0 ? v[k] : 0.0;
  };
  std::vector<Eigen::VectorXd> residual(levels_.size());  // Phi_l^T v
  std::vector<Eigen::VectorXd> update(levels_.size());    // what level l hands to the finer one
  Dims dims = fine_;
  for (std::size_t li = 0; li < levels_.size(); ++li) {
    const Level& level = levels_[li];
    const auto& axes = level.axes;
    const auto& points = level.points;
    Eigen::VectorXd along_z;
    if (li == 0) {
      restrict_axis(read_lattice, dims, 2, axes[2], points[2], along_z);
    } else {
      restrict_axis(vector_reader(residual[li - 1]), dims, 2, axes[2], points[2], along_z);
    }
    dims[2] = points[2];
    Eigen::VectorXd along_x;
    restrict_axis(vector_reader(along_z), dims, 0, axes[0], points[0], along_x);
    dims[0] = points[0];
    restrict_axis(vector_reader(along_x), dims, 1, axes[1], points[1], residual[li]);
    dims[1] = points[1];
  }

  const std::size_t last = levels_.size() - 1;
  Eigen::VectorXd compact(factor_.rows());
  for (std::size_t q = 0; q < exact_index_.size(); ++q) {
    if (exact_index_[q] >= 0)
      compact[exact_index_[q]] = residual[last][static_cast<Eigen::Index>(q)];
  }
  const Eigen::VectorXd solved = factor_.solve(compact);
  update[last].resize(residual[last].size());
  for (std::size_t q = 0; q < exact_index_.size(); ++q) {
    update[last][static_cast<Eigen::Index>(q)] =
        exact_index_[q] >= 0 ? solved[exact_index_[q]] : 0.0;
  }
  // Interpolation back, level by level (y, x, z); each finer level adds its own scaled part,
  // and the lattice's free coordinates take the last sweep's values into w.
  for (std::size_t li = levels_.size(); li-- > 0;) {
    const Level& level = levels_[li];
    const Dims finer = li == 0 ? fine_ : levels_[li - 1].points;
    Dims d = level.points;
    Eigen::VectorXd along_y;
    d[1] = finer[1];
    interpolate_axis(update[li], level.points, 1, level.axes[1], d[1], vector_writer(along_y, d));
    update[li] = Eigen::VectorXd();  // done with: its memory goes before the finer level's
    Eigen::VectorXd along_x;
    Dims dx = d;
    dx[0] = finer[0];
    interpolate_axis(along_y, d, 0, level.axes[0], dx[0], vector_writer(along_x, dx));
    if (li > 0) {
      Eigen::VectorXd& next = update[li - 1];
      interpolate_axis(along_x, dx, 2, level.axes[2], finer[2], vector_writer(next, finer));
      next += levels_[li - 1].inverse_diagonal.cwiseProduct(residual[li - 1]);
    } else {
      interpolate_axis(along_x, dx, 2, level.axes[2], finer[2],
                       [&](std::int64_t coordinate, double value) {
                         const Eigen::Index k = map.own_dof_of_coordinate(coordinate);
                         if (k >= 0) w[k] += value;
                       });
    }
  }
}

}  // namespace mresim::mess
