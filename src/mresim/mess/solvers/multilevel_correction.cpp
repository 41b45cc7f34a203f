#include "mresim/mess/solvers/multilevel_correction.hpp"

#include <algorithm>
#include <cmath>
#include <exception>
#include <stdexcept>
#include <string>

#include "mresim/mess/solvers/stiffness_terms.hpp"

namespace mresim::mess {

namespace {

// Grid fields of 3-vectors are stored node by node, node index iz + nz (ix + nx iy), as the
// lattice numbers its nodes (lattice/grid.hpp). dims = {nx, ny, nz}.
using Dims = std::array<int, 3>;

std::array<std::int64_t, 3> strides(const Dims& d) {
  return {static_cast<std::int64_t>(d[2]), static_cast<std::int64_t>(d[2]) * d[0], 1};
}

std::int64_t point_count(const Dims& d) { return static_cast<std::int64_t>(d[0]) * d[1] * d[2]; }

// Calls line(in_offset, out_offset) for every grid line along `axis`, in parallel: each line is
// one thread's, so what a line computes does not depend on the number of threads.
template <class Line>
void for_each_line(const Dims& in, const Dims& out, int axis, Line&& line) {
  const int b = axis == 0 ? 1 : 0;
  const int c = axis == 2 ? 1 : 2;
  const auto si = strides(in);
  const auto so = strides(out);
  const std::int64_t lines =
      static_cast<std::int64_t>(in[static_cast<std::size_t>(b)]) * in[static_cast<std::size_t>(c)];
#pragma omp parallel for schedule(static) if (lines * in[static_cast <std::size_t>(axis)] > 20000)
  for (std::int64_t l = 0; l < lines; ++l) {
    const std::int64_t ib = l / in[static_cast<std::size_t>(c)];
    const std::int64_t ic = l % in[static_cast<std::size_t>(c)];
    line(3 * (ib * si[static_cast<std::size_t>(b)] + ic * si[static_cast<std::size_t>(c)]),
         3 * (ib * so[static_cast<std::size_t>(b)] + ic * so[static_cast<std::size_t>(c)]));
  }
}

// Restricts a field of 3-vectors on the grid `dims` along `axis` to `level`'s points there:
// out[j] = sum_i phi_j(i) in[i] over each grid line, in index order. read(c) gives the input at
// flat index c = 3 node + component.
template <class Level, class Read>
void restrict_axis(Read&& read, const Dims& dims, int axis, const Level& level,
                   Eigen::VectorXd& out) {
  const auto& ax = level.axes[static_cast<std::size_t>(axis)];
  Dims next = dims;
  next[static_cast<std::size_t>(axis)] = level.points[static_cast<std::size_t>(axis)];
  out.resize(3 * point_count(next));
  const std::int64_t si = 3 * strides(dims)[static_cast<std::size_t>(axis)];
  const std::int64_t so = 3 * strides(next)[static_cast<std::size_t>(axis)];
  const int n_in = dims[static_cast<std::size_t>(axis)];
  const int n_out = next[static_cast<std::size_t>(axis)];
  for_each_line(dims, next, axis, [&](std::int64_t in_offset, std::int64_t out_offset) {
    for (int j = 0; j < n_out; ++j) {
      for (int a = 0; a < 3; ++a) out[out_offset + j * so + a] = 0.0;
    }
    for (int i = 0; i < n_in; ++i) {
      const double t = ax.upper[static_cast<std::size_t>(i)];
      const std::int64_t lo = out_offset + ax.lower[static_cast<std::size_t>(i)] * so;
      for (int a = 0; a < 3; ++a) {
        const double value = read(in_offset + i * si + a);
        out[lo + a] += (1.0 - t) * value;
        if (t != 0.0) out[lo + so + a] += t * value;
      }
    }
  });
}

// The transpose: interpolates `in` (on `coarse` dims, `level`'s points along `axis`) to the
// finer grid `fine` along `axis`; write(c, value) takes each fine value once.
template <class Level, class Write>
void interpolate_axis(const Eigen::VectorXd& in, const Dims& coarse, int axis, const Level& level,
                      const Dims& fine, Write&& write) {
  const auto& ax = level.axes[static_cast<std::size_t>(axis)];
  const std::int64_t si = 3 * strides(coarse)[static_cast<std::size_t>(axis)];
  const std::int64_t so = 3 * strides(fine)[static_cast<std::size_t>(axis)];
  const int n_out = fine[static_cast<std::size_t>(axis)];
  for_each_line(fine, coarse, axis, [&](std::int64_t out_offset, std::int64_t in_offset) {
    for (int i = 0; i < n_out; ++i) {
      const double t = ax.upper[static_cast<std::size_t>(i)];
      const std::int64_t lo = in_offset + ax.lower[static_cast<std::size_t>(i)] * si;
      for (int a = 0; a < 3; ++a) {
        write(out_offset + i * so + a,
              t == 0.0 ? in[lo + a] : (1.0 - t) * in[lo + a] + t * in[lo + si + a]);
      }
    }
  });
}

auto vector_reader(const Eigen::VectorXd& v) {
  return [&v](std::int64_t c) { return v[c]; };
}

// Writes into `v`, sized for the grid `dims`.
auto vector_writer(Eigen::VectorXd& v, const Dims& dims) {
  v.resize(3 * point_count(dims));
  return [&v](std::int64_t c, double value) { v[c] = value; };
}

// One rank-one term's projection onto a level: per level node, the three axes' values.
struct Entry {
  std::int64_t node;
  std::array<double, 3> value;
};

void add_entry(std::vector<Entry>& z, std::int64_t node, const std::array<double, 3>& value) {
  for (Entry& e : z) {
    if (e.node == node) {
      for (std::size_t a = 0; a < 3; ++a) e.value[a] += value[a];
      return;
    }
  }
  z.push_back({node, value});
}

constexpr int kReach = 2;  // the coarsest level's couplings reach 2 points along each axis
constexpr int kWidth = 2 * kReach + 1;
constexpr int kNeighbours = kWidth * kWidth * kWidth;

}  // namespace

MultilevelCorrection::MultilevelCorrection(const lattice::Lattice& lattice,
                                           double volume_force_factor, const DofMap& map,
                                           double force_scale, const Eigen::Matrix3Xd* state,
                                           Eigen::Index exact_limit) {
  if (exact_limit < 1) {
    throw std::invalid_argument("MultilevelCorrection: exact_limit " + std::to_string(exact_limit) +
                                " must be at least 1");
  }
  fine_ = lattice.shape.nodes;
  own_dofs_ = map.own_dofs();
  build_levels(exact_limit);
  assemble(lattice, volume_force_factor, lattice.element_length / force_scale, map, state);
}

Eigen::Index MultilevelCorrection::level_size(int level) const {
  const Level& l = levels_.at(static_cast<std::size_t>(level - 1));
  return 3 * point_count(l.points);
}

void MultilevelCorrection::build_levels(Eigen::Index exact_limit) {
  std::array<std::vector<int>, 3> planes;
  for (std::size_t a = 0; a < 3; ++a) {
    planes[a].resize(static_cast<std::size_t>(fine_[a]));
    for (int i = 0; i < fine_[a]; ++i) planes[a][static_cast<std::size_t>(i)] = i;
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
      level.points[a] = m;
    }
    // A grid of two planes per axis cannot be coarsened: the previous level is the coarsest.
    if (!coarser && !levels_.empty()) break;
    for (std::size_t a = 0; a < 3; ++a) planes[a] = level.axes[a].plane;
    levels_.push_back(std::move(level));
    // The coarsest level is solved exactly at every application, so it must also be small
    // against the lattice: at most 1/64 of its coordinates (two coarsenings where possible).
    const std::int64_t size = 3 * point_count(levels_.back().points);
    if (size <= exact_limit && 64 * size <= 3 * point_count(fine_)) break;
  }
}

namespace {

// Sums the rank-one terms c z z^T of the reference Hessian projected onto one level: the
// diagonal always, the 3 x 3 blocks of each point's neighbours (<= kReach apart) when the
// level is solved exactly.
class LevelAssembler {
 public:
  LevelAssembler(const std::array<std::vector<int>, 3>& planes, const Dims& fine,
                 const Dims& points, const DofMap& map, bool exact)
      : fine_(fine), points_(points), map_(map) {
    // Each lattice plane's bracket on this level: the composition of the levels' linear
    // interpolations is the linear interpolation in lattice coordinates (nested grids).
    for (std::size_t a = 0; a < 3; ++a) {
      const std::vector<int>& plane = planes[a];
      std::size_t j = 0;
      for (int f = 0; f < fine_[a]; ++f) {
        while (j + 2 < plane.size() && plane[j + 1] <= f) ++j;
        lower_[a].push_back(static_cast<int>(j));
        upper_[a].push_back(static_cast<double>(f - plane[j]) / (plane[j + 1] - plane[j]));
      }
    }
    const std::int64_t count = point_count(points_);
    diagonal_.assign(static_cast<std::size_t>(3 * count), 0.0);
    if (exact) blocks_.assign(static_cast<std::size_t>(count * kNeighbours * 9), 0.0);
  }

  void clear() { z_.clear(); }

  // z += sign direction_a phi_n for the free coordinates a of lattice node n.
  void add_node(std::int64_t n, const Eigen::Vector3d& direction, double sign) {
    const auto nz = static_cast<std::int64_t>(fine_[2]);
    const auto nx = static_cast<std::int64_t>(fine_[0]);
    const std::array<std::int64_t, 3> i{(n / nz) % nx, n / nz / nx, n % nz};
    for (int c = 0; c < 8; ++c) {
      std::array<std::int64_t, 3> j{};
      double w = sign;
      for (std::size_t a = 0; a < 3; ++a) {
        const bool up = ((c >> a) & 1) != 0;
        const auto f = static_cast<std::size_t>(i[a]);
        j[a] = lower_[a][f] + (up ? 1 : 0);
        w *= up ? upper_[a][f] : 1.0 - upper_[a][f];
      }
      if (w == 0.0) continue;
      const std::int64_t node =
          j[2] + points_[2] * (j[0] + static_cast<std::int64_t>(points_[0]) * j[1]);
      std::array<double, 3> value{};
      for (std::size_t a = 0; a < 3; ++a) {
        if (map_.own_dof_of_coordinate(3 * n + static_cast<std::int64_t>(a)) >= 0) {
          value[a] = w * direction[static_cast<Eigen::Index>(a)];
        }
      }
      add_entry(z_, node, value);
    }
  }

  // Adds c z z^T.
  void add_term(double c) {
    for (const Entry& e : z_) {
      for (std::size_t a = 0; a < 3; ++a) {
        diagonal_[static_cast<std::size_t>(3 * e.node) + a] += c * e.value[a] * e.value[a];
      }
    }
    if (blocks_.empty()) return;
    for (const Entry& e : z_) {
      const auto je = coordinates(e.node);
      for (const Entry& f : z_) {
        const auto jf = coordinates(f.node);
        const std::int64_t code = (jf[0] - je[0] + kReach) * kWidth * kWidth +
                                  (jf[1] - je[1] + kReach) * kWidth + (jf[2] - je[2] + kReach);
        double* block = blocks_.data() + (e.node * kNeighbours + code) * 9;
        for (std::size_t a = 0; a < 3; ++a) {
          for (std::size_t b = 0; b < 3; ++b) block[3 * a + b] += c * e.value[a] * f.value[b];
        }
      }
    }
  }

  std::array<std::int64_t, 3> coordinates(std::int64_t node) const {
    return {(node / points_[2]) % points_[0], node / points_[2] / points_[0], node % points_[2]};
  }
  const std::vector<double>& diagonal() const { return diagonal_; }
  const std::vector<double>& blocks() const { return blocks_; }

 private:
  Dims fine_;
  Dims points_;
  const DofMap& map_;
  std::array<std::vector<int>, 3> lower_;
  std::array<std::vector<double>, 3> upper_;
  std::vector<Entry> z_;
  std::vector<double> diagonal_;
  std::vector<double> blocks_;
};

// The stiffness terms of stiffness_terms.hpp, linearised at `state` (null: at rest), projected
// onto one level.
void add_stiffness(const lattice::Lattice& lattice, const Eigen::Matrix3Xd* state,
                   const DofMap& map, double volume_force_factor, double scale,
                   LevelAssembler& level) {
  for_each_stiffness_term(
      lattice, state, map, volume_force_factor, scale,
      [&level](std::int64_t i, std::int64_t j, const Eigen::Vector3d& u, double c) {
        level.clear();
        level.add_node(j, u, 1.0);
        level.add_node(i, u, -1.0);
        level.add_term(c);
      },
      [&level](const auto& element, const lattice::CellVertices& g, double c) {
        level.clear();
        for (std::size_t v = 0; v < 8; ++v) level.add_node(element[v], g[v], 1.0);
        level.add_term(c);
      });
}

}  // namespace

void MultilevelCorrection::assemble(const lattice::Lattice& lattice, double volume_force_factor,
                                    double scale, const DofMap& map,
                                    const Eigen::Matrix3Xd* state) {
  // Each level sweeps all springs and cells, and the levels are independent: one thread per
  // level, so that each level's sums come in the same order whatever the thread count.
  std::exception_ptr failure;
  const auto count = static_cast<std::int64_t>(levels_.size());
#pragma omp parallel for schedule(dynamic, 1) if (point_count(fine_) >= 20000)
  for (std::int64_t li = 0; li < count; ++li) {
    try {
      Level& level = levels_[static_cast<std::size_t>(li)];
      const bool exact = li + 1 == count;
      const std::int64_t points = point_count(level.points);
      LevelAssembler assembler({level.axes[0].plane, level.axes[1].plane, level.axes[2].plane},
                               fine_, level.points, map, exact);
      add_stiffness(lattice, state, map, volume_force_factor, scale, assembler);
      if (exact) {
        factor_coarsest(level.points, assembler.diagonal(), assembler.blocks());
        continue;
      }
      level.inverse_diagonal = Eigen::VectorXd::Zero(3 * points);
      for (std::int64_t q = 0; q < 3 * points; ++q) {
        const double d = assembler.diagonal()[static_cast<std::size_t>(q)];
        if (d > 0.0) level.inverse_diagonal[q] = 1.0 / d;
      }
    } catch (...) {
#pragma omp critical(mresim_multilevel_assembly)
      failure = std::current_exception();
    }
  }
  if (failure) std::rethrow_exception(failure);
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
    Eigen::VectorXd along_z;
    if (li == 0) {
      restrict_axis(read_lattice, dims, 2, level, along_z);
    } else {
      restrict_axis(vector_reader(residual[li - 1]), dims, 2, level, along_z);
    }
    dims[2] = level.points[2];
    Eigen::VectorXd along_x;
    restrict_axis(vector_reader(along_z), dims, 0, level, along_x);
    dims[0] = level.points[0];
    restrict_axis(vector_reader(along_x), dims, 1, level, residual[li]);
    dims[1] = level.points[1];
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
    interpolate_axis(update[li], level.points, 1, level, d, vector_writer(along_y, d));
    update[li] = Eigen::VectorXd();  // done with: its memory goes before the finer level's
    Eigen::VectorXd along_x;
    Dims dx = d;
    dx[0] = finer[0];
    interpolate_axis(along_y, d, 0, level, dx, vector_writer(along_x, dx));
    if (li > 0) {
      Eigen::VectorXd& next = update[li - 1];
      interpolate_axis(along_x, dx, 2, level, finer, vector_writer(next, finer));
      next += levels_[li - 1].inverse_diagonal.cwiseProduct(residual[li - 1]);
    } else {
      interpolate_axis(along_x, dx, 2, level, finer, [&](std::int64_t coordinate, double value) {
        const Eigen::Index k = map.own_dof_of_coordinate(coordinate);
        if (k >= 0) w[k] += value;
      });
    }
  }
}

}  // namespace mresim::mess
