#include "mresim/mess/terms/elastic_terms.hpp"

#include <omp.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "mresim/mess/lattice/volume_elements.hpp"
#include "mresim/mess/system/fixed_order.hpp"
#include "mresim/mess/terms/cell_rows.hpp"
#include "mresim/mess/terms/elastic_formulas.hpp"
#include "mresim/mess/terms/spring_rows.hpp"

namespace mresim::mess {

namespace {

lattice::CellVertices gather_vertices(const std::array<std::int32_t, 8>& element,
                                      const Eigen::Matrix3Xd& x) {
  lattice::CellVertices v;
  for (int k = 0; k < 8; ++k) v[k] = x.col(element[k]);
  return v;
}

}  // namespace

// ---------------------------------------------------------------- serial reference formulas

double spring_energy(const lattice::SpringSet& springs, const Eigen::Matrix3Xd& x) {
  double energy = 0.0;
  for (std::size_t s = 0; s < springs.size(); ++s) {
    const double stretch =
        (x.col(springs.second(s)) - x.col(springs.first[s])).norm() - springs.rest_length(s);
    energy += 0.5 * springs.stiffness(s) * stretch * stretch;  // eq. 4.62
  }
  return energy;
}

void add_spring_gradient(const lattice::SpringSet& springs, const Eigen::Matrix3Xd& x,
                         Eigen::Matrix3Xd& gradient) {
  for (std::size_t s = 0; s < springs.size(); ++s) {
    const Eigen::Vector3d r = x.col(springs.second(s)) - x.col(springs.first[s]);
    const double l = r.norm();
    // eq. 4.63: the force on the second end is -k (l - L) r^; the gradient is its negative.
    const Eigen::Vector3d g = springs.stiffness(s) * (l - springs.rest_length(s)) / l * r;
    gradient.col(springs.second(s)) += g;
    gradient.col(springs.first[s]) -= g;
  }
}

double volume_energy(const lattice::GridCells& elements, double kappa, double element_length,
                     const Eigen::Matrix3Xd& x) {
  const double v0 = element_length * element_length * element_length;
  double energy = 0.0;
  for (const auto& e : elements) {
    const double dv = lattice::cell_volume(gather_vertices(e, x)) / v0 - 1.0;
    energy += 0.5 * kappa * v0 * dv * dv;  // eq. 4.64 times V0
  }
  return energy;
}

void add_volume_gradient(const lattice::GridCells& elements, double kappa, double element_length,
                         const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& gradient,
                         double force_factor) {
  const double v0 = element_length * element_length * element_length;
  lattice::CellVertices dv_dx;
  for (const auto& e : elements) {
    const double v = lattice::cell_volume_and_gradient(gather_vertices(e, x), dv_dx);
    // eq. 4.65: dU/dx_v = kappa (V/V0 - 1) dV/dx_v (V0 cancels against the 1/V0 of V/V0).
    const double f = force_factor * kappa * (v / v0 - 1.0);
    for (int k = 0; k < 8; ++k) gradient.col(e[k]) += f * dv_dx[k];
  }
}

// ------------------------------------------------------------------------- SpringKernel

namespace {

// The energy sums of the fused kernels, bitwise those of detail::fixed_order_sums: the items
// are split into the same blocks of kSumBlock, each thread takes a contiguous run of blocks
// (own_items) and sums each of them serially in index order (OwnBlockSums), and the block sums
// are added in block order (total_of).
struct ItemRange {
  std::int64_t begin = 0;
  std::int64_t end = 0;
};

ItemRange own_items(std::int64_t items, std::int64_t thread, std::int64_t threads) {
  const std::int64_t blocks = (items + detail::kSumBlock - 1) / detail::kSumBlock;
  return {std::min(items, blocks * thread / threads * detail::kSumBlock),
          std::min(items, blocks * (thread + 1) / threads * detail::kSumBlock)};
}

// One thread's block sums of (energy, rounding); items outside its own range are ignored (a
// thread also computes some of its neighbours' items, which they sum).
class OwnBlockSums {
 public:
  OwnBlockSums(ItemRange own, std::vector<std::array<double, 2>>& partial)
      : own_(own), partial_(partial) {}
  OwnBlockSums(const OwnBlockSums&) = delete;
  OwnBlockSums& operator=(const OwnBlockSums&) = delete;
  ~OwnBlockSums() { flush(); }

  // Items must come in increasing index.
  void add(std::int64_t item, double energy, double rounding) {
    if (item < own_.begin || item >= own_.end) return;
    if (item / detail::kSumBlock != block_) {
      flush();
      block_ = item / detail::kSumBlock;
    }
    sum_[0] += energy;
    sum_[1] += rounding;
  }

 private:
  void flush() {
    if (block_ >= 0) partial_[static_cast<std::size_t>(block_)] = sum_;
    sum_ = {0.0, 0.0};
  }

  ItemRange own_;
  std::vector<std::array<double, 2>>& partial_;
  std::int64_t block_ = -1;
  std::array<double, 2> sum_{0.0, 0.0};
};

std::vector<std::array<double, 2>> block_partials(std::int64_t items) {
  return std::vector<std::array<double, 2>>(
      static_cast<std::size_t>((items + detail::kSumBlock - 1) / detail::kSumBlock), {0.0, 0.0});
}

ElasticValue total_of(const std::vector<std::array<double, 2>>& partial) {
  std::array<double, 2> total{0.0, 0.0};
  for (const auto& s : partial) {
    total[0] += s[0];
    total[1] += s[1];
  }
  return {total[0], total[1]};
}

// Runs body(i) for i < n, in parallel for large n; each i writes only its own scratch slot.
template <class Body>
void for_each_item(std::int64_t n, Body&& body) {
#pragma omp parallel for schedule(static) if (n >= detail::kParallelMinimum)
  for (std::int64_t i = 0; i < n; ++i) body(i);
}

// The spring's Hessian block B = k [(1 - L/l) I + (L/l) r^ r^T].
Eigen::Matrix3d spring_block(const lattice::SpringSet& sp, std::size_t s,
                             const Eigen::Matrix3Xd& x) {
  const Eigen::Vector3d r = x.col(sp.second(s)) - x.col(sp.first[s]);
  const double l = r.norm();
  const double ratio = sp.rest_length(s) / l;
  const Eigen::Vector3d u = r / l;
  return sp.stiffness(s) *
         ((1.0 - ratio) * Eigen::Matrix3d::Identity() + ratio * u * u.transpose());
}

// Spring s of the set at positions x (eqs. 4.62-4.63), with the rest lengths by kind.
elastic::SpringValue spring_at(const lattice::SpringSet& sp,
                               const std::array<double, 3>& rest_length, const Eigen::Matrix3Xd& x,
                               std::int64_t s) {
  const auto u = static_cast<std::size_t>(s);
  const lattice::SpringProperties::Entry& spring = sp.properties[u];  // one byte read
  const std::int64_t first = sp.first[u];
  const double l = (x.col(first + spring.index_step) - x.col(first)).norm();
  return elastic::spring_value(spring.stiffness, rest_length[static_cast<std::size_t>(spring.kind)],
                               l);
}

void check_shapes(const char* who, std::int64_t node_count, const lattice::Lattice& lat,
                  const Eigen::Matrix3Xd& x) {
  if (x.cols() != node_count || lat.node_count() != node_count) {
    throw std::invalid_argument(std::string(who) + ": positions do not match the lattice");
  }
}

}  // namespace

SpringKernel::SpringKernel(const lattice::Lattice& lat)
    : node_count_(lat.node_count()), stencil_(lat) {
  // Each node's spring along each forward offset, as its stiffness table index, offset by
  // offset (so that a row of nodes reads its springs' indices contiguously).
  const lattice::SpringProperties& properties = lat.springs.properties;
  stiffness_index_.assign(static_cast<std::size_t>(13 * node_count_), 0);
  for (std::int64_t n = 0; n < node_count_; ++n) {
    stencil_.for_each_forward_spring(n, [&](std::int64_t s, int o, std::int64_t) {
      stiffness_index_[static_cast<std::size_t>(o * node_count_ + n)] =
          properties.table_index(static_cast<std::size_t>(s));
    });
  }
  for (const auto& entry : properties.table()) stiffness_table_.push_back(entry.stiffness);
}

ElasticValue SpringKernel::evaluate(const lattice::Lattice& lat, const Eigen::Matrix3Xd& x,
                                    Eigen::Matrix3Xd* gradient) const {
  check_shapes("SpringKernel::evaluate", node_count_, lat, x);
  if (gradient != nullptr) return evaluate_with_gradient(lat, x, *gradient);
  const lattice::SpringSet& sp = lat.springs;
  // Rest lengths by kind, the values sp.rest_length(s) gives, looked up without a call.
  const std::array<double, 3> rest_length = elastic::rest_lengths(sp.element_length);
  // Energy (eq. 4.62) and its rounding scale.
  const auto sums =
      detail::fixed_order_sums(static_cast<std::int64_t>(sp.size()), [&](std::int64_t s) {
        const elastic::SpringValue value = spring_at(sp, rest_length, x, s);
        return std::array<double, 2>{value.energy, value.rounding};
      });
  return {sums[0], sums[1]};
}

namespace {

// One evaluation's spring rows (SpringKernel::evaluate_with_gradient): the grid, the positions
// as component arrays, each forward offset's rest length and stiffness indices, and the three
// steps of a row. Row r holds the nodes r nz ... r nz + nz - 1 (node n = iz + nz (ix + nx iy),
// row ix + nx iy); each row's arrays hold 13 x nz values, offset o's at o nz.
class SpringRows {
 public:
  SpringRows(const SpringStencil& stencil, const double* components,
             const std::array<double, 3>& rest_of_kind, const std::uint8_t* stiffness_index,
             const double* stiffness_table)
      : stencil_(stencil),
        nx_(stencil.shape().nx()),
        ny_(stencil.shape().ny()),
        nz_(stencil.shape().nz()),
        nodes_(stencil.node_count()),
        components_(components),
        stiffness_index_(stiffness_index),
        stiffness_table_(stiffness_table) {
    for (std::size_t o = 0; o < 13; ++o) {
      rest_length_[o] = rest_of_kind[static_cast<std::size_t>(
          lattice::kind_of_offset(lattice::kForwardNeighbours[o]))];
    }
  }

  std::int64_t nx() const { return nx_; }
  std::int64_t nz() const { return nz_; }

  // A row with its grid coordinates and first node (computed once per row, not per offset).
  struct Row {
    std::int64_t index;
    std::int64_t ix;
    std::int64_t iy;
    std::int64_t first_node;
  };
  Row row(std::int64_t index) const { return {index, index % nx_, index / nx_, index * nz_}; }

  // Tensions, energies and rounding scales of the row's springs (eqs. 4.62-4.63).
  void compute(const Row& row, double* tension, double* energy, double* rounding) const {
    const std::int64_t row_node = row.first_node;
    for (std::size_t o = 0; o < 13; ++o) {
      const auto& [dx, dy, dz] = lattice::kForwardNeighbours[o];
      if (!row_exists(row, dx, dy)) continue;
      const std::int64_t lo = std::max(0, -dz);
      const std::int64_t hi = std::min<std::int64_t>(nz_, nz_ - dz);
      const std::int64_t n = row_node + lo;
      const std::int64_t at = static_cast<std::int64_t>(o) * nz_ + lo;
      spring_rows::tensions(hi - lo, components(n), components(n + delta(o)),
                            stiffness_index_ + static_cast<std::int64_t>(o) * nodes_ + n,
                            stiffness_table_, rest_length_[o], tension + at, energy + at,
                            rounding + at);
    }
  }

  // The energies of the nodes [begin, end) of the row, in increasing spring index.
  void add_energies(const Row& row, std::int64_t begin, std::int64_t end, const double* energy,
                    const double* rounding, OwnBlockSums& sums) const {
    for (std::int64_t n = begin; n < end; ++n) {
      const std::int64_t iz = n - row.first_node;
      stencil_.for_each_forward_spring(n, [&](std::int64_t s, int o, std::int64_t) {
        sums.add(s, energy[o * nz_ + iz], rounding[o * nz_ + iz]);
      });
    }
  }

  // g += the backward springs' contributions for the row's nodes [first_iz, end_iz), offset by
  // offset in the stencil's order; tensions_of(r) gives row r's tensions.
  template <class Tensions>
  void add_backward(const Row& row, std::int64_t first_iz, std::int64_t end_iz,
                    Tensions&& tensions_of, double* gx, double* gy, double* gz) const {
    for (const int o : stencil_.backward_order()) {
      const auto& [dx, dy, dz] = lattice::kForwardNeighbours[static_cast<std::size_t>(o)];
      if (!row_exists(row, -dx, -dy)) continue;
      const std::int64_t lo = std::max<std::int64_t>(first_iz, dz);
      const std::int64_t hi = std::min<std::int64_t>(end_iz, nz_ + dz);
      if (lo >= hi) continue;
      const std::int64_t n = row.first_node + lo;
      const double* from = tensions_of(row.index - dx - nx_ * dy) + o * nz_ + lo - dz;
      spring_rows::add_backward(hi - lo, from, components(n - delta(static_cast<std::size_t>(o))),
                                components(n), gx + lo, gy + lo, gz + lo);
    }
  }

  // g -= the forward springs' contributions for the row's nodes [first_iz, end_iz).
  void subtract_forward(const Row& row, std::int64_t first_iz, std::int64_t end_iz,
                        const double* tension, double* gx, double* gy, double* gz) const {
    for (std::size_t o = 0; o < 13; ++o) {
      const auto& [dx, dy, dz] = lattice::kForwardNeighbours[o];
      if (!row_exists(row, dx, dy)) continue;
      const std::int64_t lo = std::max<std::int64_t>(first_iz, -dz);
      const std::int64_t hi = std::min<std::int64_t>(end_iz, nz_ - dz);
      if (lo >= hi) continue;
      const std::int64_t n = row.first_node + lo;
      spring_rows::subtract_forward(hi - lo, tension + static_cast<std::int64_t>(o) * nz_ + lo,
                                    components(n), components(n + delta(o)), gx + lo, gy + lo,
                                    gz + lo);
    }
  }

 private:
  // Whether the row (dx, dy) away from `row` lies in the grid.
  bool row_exists(const Row& row, int dx, int dy) const {
    const std::int64_t ix = row.ix + dx;
    const std::int64_t iy = row.iy + dy;
    return ix >= 0 && ix < nx_ && iy >= 0 && iy < ny_;
  }
  std::int64_t delta(std::size_t o) const { return stencil_.deltas()[o]; }
  spring_rows::Components components(std::int64_t n) const {
    return {components_ + n, components_ + nodes_ + n, components_ + 2 * nodes_ + n};
  }

  const SpringStencil& stencil_;
  std::int64_t nx_;
  std::int64_t ny_;
  std::int64_t nz_;
  std::int64_t nodes_;
  const double* components_;  // x, y and z of every node, nodes_ apart
  const std::uint8_t* stiffness_index_;
  const double* stiffness_table_;
  std::array<double, 13> rest_length_{};  // by forward offset
};

// The nodes a thread gathers, [begin, end): those whose first spring lies in its own energy
// blocks `own` (the last thread also takes the last node, which has none).
ItemRange nodes_of_thread(const SpringStencil& stencil, ItemRange own, bool last_thread) {
  const auto first_node_from = [&](std::int64_t spring) {
    std::int64_t lo = 0;
    std::int64_t hi = stencil.node_count();
    while (lo < hi) {  // the first node whose first spring is >= spring
      const std::int64_t mid = lo + (hi - lo) / 2;
      if (stencil.first_spring(mid) < spring) {
        lo = mid + 1;
      } else {
        hi = mid;
      }
    }
    return lo;
  };
  return {first_node_from(own.begin),
          last_thread ? stencil.node_count() : first_node_from(own.end)};
}

// Copies columns row_node + [begin, end) of the 3 x N matrix m into or out of a row's
// component arrays (entries [begin, end)).
void load_row(const Eigen::Matrix3Xd& m, std::int64_t row_node, std::int64_t begin,
              std::int64_t end, double* gx, double* gy, double* gz) {
  for (std::int64_t i = begin; i < end; ++i) {
    gx[i] = m(0, row_node + i);
    gy[i] = m(1, row_node + i);
    gz[i] = m(2, row_node + i);
  }
}
void store_row(const double* gx, const double* gy, const double* gz, std::int64_t row_node,
               std::int64_t begin, std::int64_t end, Eigen::Matrix3Xd& m) {
  for (std::int64_t i = begin; i < end; ++i) {
    m(0, row_node + i) = gx[i];
    m(1, row_node + i) = gy[i];
    m(2, row_node + i) = gz[i];
  }
}

}  // namespace

// The springs row by row along z, one SIMD lane per node (spring_rows.hpp), with bitwise the
// results of a tension pass over all springs, a scratch array and SpringStencil::gather, for
// any thread count:
//  - each node adds its springs' contributions in the stencil's order (its backward springs by
//    decreasing index step, then its forward springs in offset order): the row loops go offset
//    by offset in that order, and every lane does the same operations as the scalar gather;
//  - the energy is summed in the blocks of detail::fixed_order_sums: each thread takes a
//    contiguous run of the blocks, computes whole rows, and adds its own springs' energies in
//    increasing spring index.
// A row's tensions are kept, per offset, in a ring of the last nx + 2 rows: a node's backward
// springs come from rows at most nx + 1 below its own. Positions are copied once into three
// component arrays. A thread first computes the rows below its first node whose springs reach
// it (the previous thread computes them too).
ElasticValue SpringKernel::evaluate_with_gradient(const lattice::Lattice& lat,
                                                  const Eigen::Matrix3Xd& x,
                                                  Eigen::Matrix3Xd& gradient) const {
  const std::int64_t springs = stencil_.spring_count();
  const std::int64_t nodes = stencil_.node_count();
  std::vector<std::array<double, 2>> partial = block_partials(springs);
  const bool parallel = springs >= detail::kParallelMinimum;
  const std::int64_t max_threads = parallel ? omp_get_max_threads() : 1;
  components_.resize(static_cast<std::size_t>(3 * nodes));
  const SpringRows rows(stencil_, components_.data(),
                        elastic::rest_lengths(lat.springs.element_length), stiffness_index_.data(),
                        stiffness_table_.data());
  const std::int64_t nx = rows.nx();
  const std::int64_t nz = rows.nz();
  const std::int64_t ring_rows = nx + 2;
  // Per thread: the tension ring, the current row's energies and roundings (13 nz each) and
  // its nodes' gradients (3 nz).
  const std::int64_t scratch_per_thread = (ring_rows * 13 + 26 + 3) * nz;
  row_scratch_.resize(static_cast<std::size_t>(max_threads * scratch_per_thread));

#pragma omp parallel if (parallel)
  {
#pragma omp for schedule(static)
    for (std::int64_t n = 0; n < nodes; ++n) {
      components_[static_cast<std::size_t>(n)] = x(0, n);
      components_[static_cast<std::size_t>(nodes + n)] = x(1, n);
      components_[static_cast<std::size_t>(2 * nodes + n)] = x(2, n);
    }
    const auto threads = static_cast<std::int64_t>(omp_get_num_threads());
    const auto thread = static_cast<std::int64_t>(omp_get_thread_num());
    const ItemRange own = own_items(springs, thread, threads);
    const ItemRange gathered = nodes_of_thread(stencil_, own, thread + 1 == threads);
    // The node before the first gathered one may have springs on both sides of own.begin.
    const std::int64_t energy_begin = std::max<std::int64_t>(0, gathered.begin - 1);
    double* const scratch = row_scratch_.data() + thread * scratch_per_thread;
    double* const energy = scratch + ring_rows * 13 * nz;
    double* const rounding = energy + 13 * nz;
    double* const gx = rounding + 13 * nz;
    double* const gy = gx + nz;
    double* const gz = gy + nz;
    const auto tensions_of = [&](std::int64_t row) {
      return scratch + (row % ring_rows) * 13 * nz;
    };

    OwnBlockSums sums(own, partial);
    const std::int64_t row_end = gathered.end > energy_begin ? (gathered.end - 1) / nz + 1 : 0;
    for (std::int64_t index = std::max<std::int64_t>(0, energy_begin / nz - nx - 1);
         index < row_end; ++index) {
      const SpringRows::Row row = rows.row(index);
      const std::int64_t row_node = row.first_node;
      rows.compute(row, tensions_of(index), energy, rounding);
      rows.add_energies(row, std::max(row_node, energy_begin),
                        std::min(row_node + nz, gathered.end), energy, rounding, sums);
      // The gradient of this thread's nodes in the row.
      const std::int64_t first_iz = std::max(row_node, gathered.begin) - row_node;
      const std::int64_t end_iz = std::min(row_node + nz, gathered.end) - row_node;
      if (first_iz >= end_iz) continue;
      load_row(gradient, row_node, first_iz, end_iz, gx, gy, gz);
      rows.add_backward(row, first_iz, end_iz, tensions_of, gx, gy, gz);
      rows.subtract_forward(row, first_iz, end_iz, tensions_of(index), gx, gy, gz);
      store_row(gx, gy, gz, row_node, first_iz, end_iz, gradient);
    }
  }
  return total_of(partial);
}

void SpringKernel::add_hessian_product(const lattice::Lattice& lat, const Eigen::Matrix3Xd& x,
                                       const Eigen::Matrix3Xd& v, Eigen::Matrix3Xd& out) const {
  check_shapes("SpringKernel::add_hessian_product", node_count_, lat, x);
  const lattice::SpringSet& sp = lat.springs;
  scratch_.resize(3 * sp.size());
  const std::array<double, 3> rest_length = elastic::rest_lengths(sp.element_length);
  // w_s = B_s (v_j - v_i) = k [(1 - L/l) dv + (L/l) u (u . dv)], u = r/l, without forming B:
  // +w_s on the second end, -w_s on the first.
  for_each_item(static_cast<std::int64_t>(sp.size()), [&](std::int64_t s) {
    const auto i = static_cast<std::size_t>(s);
    const lattice::SpringProperties::Entry& spring = sp.properties[i];
    const std::int64_t first = sp.first[i];
    const std::int64_t second = first + spring.index_step;
    const Eigen::Vector3d r = x.col(second) - x.col(first);
    const double l = r.norm();
    const double ratio = rest_length[static_cast<std::size_t>(spring.kind)] / l;
    const Eigen::Vector3d u = r / l;
    const Eigen::Vector3d dv = v.col(second) - v.col(first);
    Eigen::Map<Eigen::Vector3d>(scratch_.data() + 3 * s) =
        spring.stiffness * ((1.0 - ratio) * dv + (ratio * u.dot(dv)) * u);
  });
  stencil_.gather(out, [&](std::int64_t s, std::int64_t, std::int64_t) {
    return Eigen::Vector3d(Eigen::Map<const Eigen::Vector3d>(scratch_.data() + 3 * s));
  });
}

void SpringKernel::add_hessian_blocks(const lattice::Lattice& lat, const Eigen::Matrix3Xd& x,
                                      HessianBlockSink& sink) {
  const lattice::SpringSet& sp = lat.springs;
  const bool filtered = sink.filters_nodes();
  for (std::size_t s = 0; s < sp.size(); ++s) {
    const std::int64_t i = sp.first[s];
    const std::int64_t j = sp.second(s);
    if (filtered && !sink.takes_node(i) && !sink.takes_node(j)) continue;  // no block kept
    const Eigen::Matrix3d block = spring_block(sp, s, x);
    sink.add(i, i, block);
    sink.add(j, j, block);
    sink.add(i, j, -block);
    sink.add(j, i, -block);
  }
}

void SpringKernel::add_hessian_entries(const lattice::Lattice& lat, const Eigen::Matrix3Xd& x,
                                       std::vector<Eigen::Triplet<double>>& entries) {
  entries.reserve(entries.size() + 36 * lat.springs.size());
  TripletSink sink(entries);
  add_hessian_blocks(lat, x, sink);
}

// ------------------------------------------------------------------------- VolumeKernel

namespace {

// The Hessian product of one cell as its three coefficient vectors t_a, t_b, t_c (the
// product at vertex k is s_a t_a + s_b t_b + s_c t_c), see elastic_terms.hpp.
std::array<Eigen::Vector3d, 3> cell_hessian_terms(const lattice::EdgeVectors& e,
                                                  const lattice::EdgeVectors& d, double kappa,
                                                  double v0, double force_factor) {
  const Eigen::Vector3d bxc = e.b.cross(e.c);
  const Eigen::Vector3d cxa = e.c.cross(e.a);
  const Eigen::Vector3d axb = e.a.cross(e.b);
  const double dv = e.a.dot(bxc) / v0 - 1.0;
  const double d_volume = d.a.dot(bxc) + d.b.dot(cxa) + d.c.dot(axb);  // dV/dx . v
  const double f1 = 0.25 * force_factor * kappa * d_volume / v0;
  const double f2 = 0.25 * force_factor * kappa * dv;
  return {f1 * bxc + f2 * (d.b.cross(e.c) + e.b.cross(d.c)),
          f1 * cxa + f2 * (d.c.cross(e.a) + e.c.cross(d.a)),
          f1 * axb + f2 * (d.a.cross(e.b) + e.a.cross(d.b))};
}

// Signs of lattice::cell_volume_and_gradient: bit 1 = +x face (a), bit 2 = +y (b), bit 0 = +z.
Eigen::Vector3d vertex_signs(int v) {
  return {(v & 2) ? 1.0 : -1.0, (v & 4) ? 1.0 : -1.0, (v & 1) ? 1.0 : -1.0};
}

}  // namespace

VolumeKernel::VolumeKernel(const lattice::Lattice& lat)
    : node_count_(lat.node_count()), stencil_(lat.shape) {}

void VolumeKernel::gather(const std::vector<double>& terms, Eigen::Matrix3Xd& out) const {
  stencil_.gather(out, [&](std::int64_t cell, int v) {
    return elastic::vertex_gradient(terms.data() + 9 * cell, v);
  });
}

ElasticValue VolumeKernel::evaluate(const lattice::Lattice& lat, const Eigen::Matrix3Xd& x,
                                    double force_factor, Eigen::Matrix3Xd* gradient) const {
  check_shapes("VolumeKernel::evaluate", node_count_, lat, x);
  const auto cells = static_cast<std::int64_t>(lat.elements.size());
  const double kappa = lat.polymer.kappa;
  const double v0 = std::pow(lat.element_length, 3);
  if (gradient != nullptr) return evaluate_with_gradient(lat, x, force_factor, *gradient);
  // Energy (eq. 4.64 x V0) and its rounding scale.
  const auto sums = detail::fixed_order_sums(cells, [&](std::int64_t c) {
    const elastic::CellValue value =
        elastic::cell_value(gather_vertices(lat.elements[static_cast<std::size_t>(c)], x), kappa,
                            v0, force_factor, nullptr);
    return std::array<double, 2>{value.energy, value.rounding};
  });
  return {sums[0], sums[1]};
}

namespace {

// One thread's scratch for the cell layers along y (VolumeKernel::evaluate_with_gradient): two
// node planes of positions (plane iy in slot iy mod 2; a plane of constant y is nx z-lines, z
// fastest, one contiguous run of the node numbering, copied into three component arrays), two
// layers of cell coefficients (layer cy in slot cy mod 2, nine arrays over the layer's cells,
// cz fastest), the layer's energies and roundings, and one node line's gradients.
class CellLayers {
 public:
  CellLayers(const lattice::GridShape& shape, double* scratch)
      : nx_(shape.nx()),
        ny_(shape.ny()),
        nz_(shape.nz()),
        line_cells_(nz_ - 1),
        layer_((nx_ - 1) * line_cells_),
        plane_(nx_ * nz_),
        planes_(scratch),
        coefficients_(planes_ + 6 * plane_),   // two planes of three components
        energy_(coefficients_ + 18 * layer_),  // two layers of nine coefficients
        rounding_(energy_ + layer_),
        gx_(rounding_ + layer_),
        gy_(gx_ + nz_),
        gz_(gy_ + nz_) {}

  // Doubles of scratch one thread needs.
  static std::int64_t scratch_size(const lattice::GridShape& shape) {
    const std::int64_t plane = std::int64_t{shape.nx()} * shape.nz();
    const std::int64_t layer = std::int64_t{shape.nx() - 1} * (shape.nz() - 1);
    // Two planes of three components, two layers of nine coefficients, a layer's energies and
    // roundings, a node line's gradients.
    return 6 * plane + 20 * layer + 3 * std::int64_t{shape.nz()};
  }

  // Copies node plane iy of x into its slot.
  void load_plane(const Eigen::Matrix3Xd& x, std::int64_t iy) {
    double* const p = plane_of(iy);
    const double* const source = x.data() + 3 * plane_ * iy;
    for (std::int64_t k = 0; k < plane_; ++k) {
      p[k] = source[3 * k];
      p[plane_ + k] = source[3 * k + 1];
      p[2 * plane_ + k] = source[3 * k + 2];
    }
  }

  // The coefficients of layer cy (planes cy and cy + 1 loaded), one z-line of cells at a time;
  // with `cells` (energy and rounding per cell, in cell index order) the cells' energies too.
  void compute_layer(std::int64_t cy, double kappa, double v0, double force_factor,
                     std::array<double, 2>* cells) {
    for (std::int64_t cx = 0; cx < nx_ - 1; ++cx) {
      cell_rows::Corners corners{};
      for (std::size_t v = 0; v < 8; ++v) {  // local vertex v = 2 dx + 4 dy + dz
        const auto dx = static_cast<std::int64_t>((v >> 1U) & 1U);
        const auto dy = static_cast<std::int64_t>((v >> 2U) & 1U);
        const auto dz = static_cast<std::int64_t>(v & 1U);
        const double* p = plane_of(cy + dy) + nz_ * (cx + dx) + dz;
        corners.x[v] = p;
        corners.y[v] = p + plane_;
        corners.z[v] = p + 2 * plane_;
      }
      const std::int64_t line = line_cells_ * cx;
      cell_rows::Coefficients<double*> t{};
      for (std::size_t k = 0; k < 9; ++k) {
        t[k] = layer_of(cy) + line + static_cast<std::int64_t>(k) * layer_;
      }
      cell_rows::coefficients(line_cells_, corners, kappa, v0, force_factor, t, energy_ + line,
                              rounding_ + line);
    }
    if (cells == nullptr) return;
    // Cell (cx, cy, cz) is cx + Cx (cy + Cy cz): each cz's row of the layer is contiguous there.
    const std::int64_t cells_x = nx_ - 1;
    const std::int64_t cells_y = ny_ - 1;
    for (std::int64_t cz = 0; cz < line_cells_; ++cz) {
      std::array<double, 2>* const row = cells + cells_x * (cy + cells_y * cz);
      for (std::int64_t cx = 0; cx < cells_x; ++cx) {
        row[cx] = {energy_[line_cells_ * cx + cz], rounding_[line_cells_ * cx + cz]};
      }
    }
  }

  // Node plane iy adds its cells' contributions (layers iy - 1 and iy, those in the grid), each
  // node z-line one vertex offset at a time in CellStencil's order.
  void gather_plane(std::int64_t iy, Eigen::Matrix3Xd& gradient) {
    const std::int64_t layers = ny_ - 1;
    for (std::int64_t ix = 0; ix < nx_; ++ix) {
      double* const g = gradient.data() + 3 * (plane_ * iy + nz_ * ix);
      for (std::int64_t iz = 0; iz < nz_; ++iz) {
        gx_[iz] = g[3 * iz];
        gy_[iz] = g[3 * iz + 1];
        gz_[iz] = g[3 * iz + 2];
      }
      for (const auto& [dx, dy, dz] : kCellsOfNode) {  // cell (ix - dx, iy - dy, iz - dz)
        const std::int64_t cx = ix - dx;
        const std::int64_t cy = iy - dy;
        if (cx < 0 || cx >= nx_ - 1 || cy < 0 || cy >= layers) continue;
        const double* const line = layer_of(cy) + line_cells_ * cx;
        cell_rows::Coefficients<const double*> t{};
        for (std::size_t k = 0; k < 9; ++k) t[k] = line + static_cast<std::int64_t>(k) * layer_;
        // The node is local vertex 2 dx + 4 dy + dz: signs s_a, s_b, s_c by dx, dy, dz.
        cell_rows::add_vertex_gradient(line_cells_, t, dx == 1 ? 1.0 : -1.0, dy == 1 ? 1.0 : -1.0,
                                       dz == 1 ? 1.0 : -1.0, gx_ + dz, gy_ + dz, gz_ + dz);
      }
      for (std::int64_t iz = 0; iz < nz_; ++iz) {
        g[3 * iz] = gx_[iz];
        g[3 * iz + 1] = gy_[iz];
        g[3 * iz + 2] = gz_[iz];
      }
    }
  }

 private:
  double* plane_of(std::int64_t iy) const { return planes_ + (iy & 1) * 3 * plane_; }
  double* layer_of(std::int64_t cy) const { return coefficients_ + (cy & 1) * 9 * layer_; }

  std::int64_t nx_;
  std::int64_t ny_;
  std::int64_t nz_;
  std::int64_t line_cells_;  // cells along z
  std::int64_t layer_;       // cells per layer
  std::int64_t plane_;       // nodes per plane
  double* planes_;
  double* coefficients_;
  double* energy_;
  double* rounding_;
  double* gx_;
  double* gy_;
  double* gz_;
};

}  // namespace

// Every cell's gradient coefficients (eqs. 4.66-4.69, elastic::cell_value) are computed once
// and gathered by its eight vertices in CellStencil::gather's order, and the energy is summed
// in the blocks of detail::fixed_order_sums: bitwise the results of a pass over all cells into
// a scratch array (9 doubles per cell) and a gather, for any thread count, without that array.
// The work runs in layers of constant y, the slowest axis of the node numbering, so that a
// node plane and its gradients are contiguous runs of memory, and along z-lines, one SIMD lane
// per cell or node (cell_rows.hpp, CellLayers); the nodes of plane iy hold cells of layers
// iy - 1 and iy only. Each thread takes a contiguous run of the node planes, computes the
// layers they need in order into two layer buffers (layer cy in buffer cy mod 2), the layer
// below its first plane too (which the thread before also computes), and gathers plane iy once
// layer iy is done. Cells are numbered layer by layer along z (cx + Cx (cy + Cy cz)), across
// the y-layers, so each cell's energy and rounding go into an array in cell order (from the
// thread that owns its layer), summed in the blocks afterwards.
ElasticValue VolumeKernel::evaluate_with_gradient(const lattice::Lattice& lat,
                                                  const Eigen::Matrix3Xd& x, double force_factor,
                                                  Eigen::Matrix3Xd& gradient) const {
  const auto cells = static_cast<std::int64_t>(lat.elements.size());
  if (cells == 0) return {0.0, 0.0};
  const double kappa = lat.polymer.kappa;
  const double v0 = std::pow(lat.element_length, 3);
  const std::int64_t ny = lat.shape.ny();
  const std::int64_t layers = ny - 1;
  const bool parallel = cells >= detail::kParallelMinimum;
  const std::int64_t max_threads = parallel ? omp_get_max_threads() : 1;
  const std::int64_t scratch_per_thread = CellLayers::scratch_size(lat.shape);
  layer_buffers_.resize(static_cast<std::size_t>(max_threads * scratch_per_thread));
  cell_energies_.resize(static_cast<std::size_t>(cells));

#pragma omp parallel if (parallel)
  {
    const auto threads = static_cast<std::int64_t>(omp_get_num_threads());
    const auto thread = static_cast<std::int64_t>(omp_get_thread_num());
    // Node planes [plane_begin, plane_end); the layers from the one below the first plane
    // through the last plane's; the energies of the layers of its own planes.
    const std::int64_t plane_begin = ny * thread / threads;
    const std::int64_t plane_end = ny * (thread + 1) / threads;
    const std::int64_t layer_begin = std::max<std::int64_t>(0, plane_begin - 1);
    const std::int64_t layer_end = std::min(layers, plane_end);
    CellLayers buffers(lat.shape, layer_buffers_.data() + thread * scratch_per_thread);
    if (layer_begin < layer_end) buffers.load_plane(x, layer_begin);
    for (std::int64_t cy = layer_begin; cy < layer_end; ++cy) {
      buffers.load_plane(x, cy + 1);
      buffers.compute_layer(cy, kappa, v0, force_factor,
                            cy >= plane_begin ? cell_energies_.data() : nullptr);
      if (cy >= plane_begin) buffers.gather_plane(cy, gradient);
    }
    // The top plane holds cells of the last layer only.
    if (plane_end == ny && plane_begin <= ny - 1) buffers.gather_plane(ny - 1, gradient);
  }
  const auto sums = detail::fixed_order_sums(
      cells, [&](std::int64_t c) { return cell_energies_[static_cast<std::size_t>(c)]; });
  return {sums[0], sums[1]};
}

void VolumeKernel::add_hessian_product(const lattice::Lattice& lat, const Eigen::Matrix3Xd& x,
                                       double force_factor, const Eigen::Matrix3Xd& v,
                                       Eigen::Matrix3Xd& out) const {
  check_shapes("VolumeKernel::add_hessian_product", node_count_, lat, x);
  const auto cells = static_cast<std::int64_t>(lat.elements.size());
  const double v0 = std::pow(lat.element_length, 3);
  scratch_.resize(static_cast<std::size_t>(9 * cells));
  // Row by row along x, so that each cell's nodes come from its row's first corner without a
  // division per cell (the scratch entries do not depend on the loop's order).
  const std::int64_t row_length = lat.shape.nx() - 1;
  const std::int64_t rows = row_length > 0 ? cells / row_length : 0;
  const std::int64_t corner_step = lat.shape.nz();
#pragma omp parallel for schedule(static) if (cells >= detail::kParallelMinimum)
  for (std::int64_t row = 0; row < rows; ++row) {
    std::int64_t corner = lat.elements.corner(row * row_length);
    for (std::int64_t c = row * row_length; c < (row + 1) * row_length;
         ++c, corner += corner_step) {
      const lattice::GridCells::Cell element = lat.elements.cell_at(corner);
      const std::array<Eigen::Vector3d, 3> t =
          cell_hessian_terms(lattice::averaged_edge_vectors(gather_vertices(element, x)),
                             lattice::averaged_edge_vectors(gather_vertices(element, v)),
                             lat.polymer.kappa, v0, force_factor);
      for (int k = 0; k < 3; ++k)
        Eigen::Map<Eigen::Vector3d>(scratch_.data() + 9 * c + 3 * std::int64_t{k}) = t[k];
    }
  }
  gather(scratch_, out);
}

void VolumeKernel::add_hessian_blocks(const lattice::Lattice& lat, const Eigen::Matrix3Xd& x,
                                      double force_factor, HessianBlockSink& sink) {
  const double v0 = std::pow(lat.element_length, 3);
  // The averaged edge vectors of each unit direction (vertex l, axis b): the same for every
  // cell, as the edge averaging is linear.
  std::array<lattice::EdgeVectors, 24> unit_edges;
  for (std::size_t column = 0; column < unit_edges.size(); ++column) {
    lattice::CellVertices unit;
    for (int k = 0; k < 8; ++k) unit[k] = Eigen::Vector3d::Zero();
    unit[column / 3][static_cast<Eigen::Index>(column % 3)] = 1.0;
    unit_edges[column] = lattice::averaged_edge_vectors(unit);
  }
  Eigen::Matrix<double, 24, 24> cell;
  const bool filtered = sink.filters_nodes();
  for (const auto& element : lat.elements) {
    if (filtered && std::none_of(element.begin(), element.end(),
                                 [&](std::int64_t n) { return sink.takes_node(n); })) {
      continue;  // no block of this cell is kept
    }
    const lattice::EdgeVectors e = lattice::averaged_edge_vectors(gather_vertices(element, x));
    // Column (l, b) of the cell's block: its product with the unit vector of that coordinate.
    for (Eigen::Index column = 0; column < 24; ++column) {
      const std::array<Eigen::Vector3d, 3> t = cell_hessian_terms(
          e, unit_edges[static_cast<std::size_t>(column)], lat.polymer.kappa, v0, force_factor);
      for (Eigen::Index k = 0; k < 8; ++k) {
        const Eigen::Vector3d s = vertex_signs(static_cast<int>(k));
        cell.block<3, 1>(3 * k, column) = s[0] * t[0] + s[1] * t[1] + s[2] * t[2];
      }
    }
    for (Eigen::Index k = 0; k < 8; ++k) {
      for (Eigen::Index l = 0; l < 8; ++l) {
        sink.add(element[static_cast<std::size_t>(k)], element[static_cast<std::size_t>(l)],
                 cell.block<3, 3>(3 * k, 3 * l));
      }
    }
  }
}

void VolumeKernel::add_hessian_entries(const lattice::Lattice& lat, const Eigen::Matrix3Xd& x,
                                       double force_factor,
                                       std::vector<Eigen::Triplet<double>>& entries) {
  entries.reserve(entries.size() + 576 * lat.elements.size());
  TripletSink sink(entries);
  add_hessian_blocks(lat, x, force_factor, sink);
}

// ------------------------------------------------------------------------- ElasticTerms

ElasticTerms::ElasticTerms(const lattice::Lattice& lat, ElasticTermSettings settings)
    : settings_(settings), springs_(lat), volume_(lat) {}

ElasticEnergies ElasticTerms::evaluate(const lattice::Lattice& lat, const Eigen::Matrix3Xd& x,
                                       Eigen::Matrix3Xd* gradient) const {
  if (gradient != nullptr) gradient->setZero(3, x.cols());
  const ElasticValue s = springs_.evaluate(lat, x, gradient);
  const ElasticValue v = volume_.evaluate(lat, x, settings_.volume_force_factor, gradient);
  return {s.energy, v.energy, s.rounding, v.rounding};
}

}  // namespace mresim::mess
