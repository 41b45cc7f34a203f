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

// The springs row by row along z (node n = iz + nz (ix + nx iy), row ix + nx iy), one SIMD lane
// per node (spring_rows.hpp), with bitwise the results of a tension pass over all springs, a
// scratch array and SpringStencil::gather, for any thread count:
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
  const std::array<double, 3> rest_of_kind = elastic::rest_lengths(lat.springs.element_length);
  const bool parallel = springs >= detail::kParallelMinimum;
  const std::int64_t max_threads = parallel ? omp_get_max_threads() : 1;
  const int nx = stencil_.shape().nx();
  const int ny = stencil_.shape().ny();
  const int nz = stencil_.shape().nz();
  const std::array<std::int64_t, 13>& delta = stencil_.deltas();
  std::array<double, 13> rest_length{};  // by forward offset
  for (std::size_t o = 0; o < 13; ++o) {
    rest_length[o] = rest_of_kind[static_cast<std::size_t>(
        lattice::kind_of_offset(lattice::kForwardNeighbours[o]))];
  }
  const std::int64_t ring_rows = nx + 2;
  // Per thread: the tension ring, the current row's energies and roundings (13 nz each) and
  // its nodes' gradients (3 nz).
  const std::int64_t scratch_per_thread = (ring_rows * 13 + 26 + 3) * std::int64_t{nz};
  row_scratch_.resize(static_cast<std::size_t>(max_threads * scratch_per_thread));
  components_.resize(static_cast<std::size_t>(3 * nodes));
  double* const cx = components_.data();
  double* const cy = cx + nodes;
  double* const cz = cy + nodes;
  const auto at = [&](std::int64_t n) { return spring_rows::Components{cx + n, cy + n, cz + n}; };

#pragma omp parallel if (parallel)
  {
#pragma omp for schedule(static)
    for (std::int64_t n = 0; n < nodes; ++n) {
      cx[n] = x(0, n);
      cy[n] = x(1, n);
      cz[n] = x(2, n);
    }
    const auto threads = static_cast<std::int64_t>(omp_get_num_threads());
    const auto thread = static_cast<std::int64_t>(omp_get_thread_num());
    // This thread's energy blocks, their springs `own`, and the nodes whose first spring lies
    // there (the last thread also takes the last node, which has none): it gathers those.
    const ItemRange own = own_items(springs, thread, threads);
    const auto first_node_from = [&](std::int64_t spring) {
      std::int64_t lo = 0;
      std::int64_t hi = nodes;
      while (lo < hi) {  // the first node whose first spring is >= spring
        const std::int64_t mid = lo + (hi - lo) / 2;
        if (stencil_.first_spring(mid) < spring) {
          lo = mid + 1;
        } else {
          hi = mid;
        }
      }
      return lo;
    };
    const std::int64_t node_begin = first_node_from(own.begin);
    const std::int64_t node_end = thread + 1 == threads ? nodes : first_node_from(own.end);
    // The node before node_begin may have springs on both sides of own.begin.
    const std::int64_t energy_begin = std::max<std::int64_t>(0, node_begin - 1);
    double* const scratch = row_scratch_.data() + thread * scratch_per_thread;
    double* const energy = scratch + ring_rows * 13 * nz;
    double* const rounding = energy + 13 * nz;
    double* const gx = rounding + 13 * nz;
    double* const gy = gx + nz;
    double* const gz = gy + nz;
    const auto tensions_of_row = [&](std::int64_t row) {
      return scratch + (row % ring_rows) * 13 * nz;
    };

    OwnBlockSums sums(own, partial);
    const std::int64_t row_end = node_end > energy_begin ? (node_end - 1) / nz + 1 : 0;
    for (std::int64_t row = std::max<std::int64_t>(0, energy_begin / nz - nx - 1); row < row_end;
         ++row) {
      const int ix = static_cast<int>(row % nx);
      const int iy = static_cast<int>(row / nx);
      const std::int64_t row_node = row * nz;
      double* const tension = tensions_of_row(row);
      // Tensions and energies of the row's springs, offset by offset.
      for (std::size_t o = 0; o < 13; ++o) {
        const auto& [dx, dy, dz] = lattice::kForwardNeighbours[o];
        if (ix + dx < 0 || ix + dx >= nx || iy + dy < 0 || iy + dy >= ny) continue;
        const std::int64_t lo = std::max(0, -dz);
        const std::int64_t hi = std::min(nz, nz - dz);
        const std::int64_t n = row_node + lo;
        spring_rows::tensions(hi - lo, at(n), at(n + delta[o]),
                              stiffness_index_.data() + static_cast<std::int64_t>(o) * nodes + n,
                              stiffness_table_.data(), rest_length[o], tension + o * nz + lo,
                              energy + o * nz + lo, rounding + o * nz + lo);
      }
      // The energy of this thread's springs, in increasing spring index.
      const std::int64_t sum_begin = std::max(row_node, energy_begin);
      const std::int64_t sum_end = std::min(row_node + nz, node_end);
      for (std::int64_t n = sum_begin; n < sum_end; ++n) {
        const std::int64_t iz = n - row_node;
        stencil_.for_each_forward_spring(n, [&](std::int64_t s, int o, std::int64_t) {
          sums.add(s, energy[o * nz + iz], rounding[o * nz + iz]);
        });
      }
      // The gradient of this thread's nodes in the row.
      const std::int64_t lo_node = std::max(row_node, node_begin);
      const std::int64_t hi_node = std::min(row_node + nz, node_end);
      if (lo_node >= hi_node) continue;
      const std::int64_t first_iz = lo_node - row_node;
      const std::int64_t end_iz = hi_node - row_node;
      for (std::int64_t iz = first_iz; iz < end_iz; ++iz) {
        gx[iz] = gradient(0, row_node + iz);
        gy[iz] = gradient(1, row_node + iz);
        gz[iz] = gradient(2, row_node + iz);
      }
      for (const int o : stencil_.backward_order()) {  // springs from the nodes below
        const auto& [dx, dy, dz] = lattice::kForwardNeighbours[static_cast<std::size_t>(o)];
        if (ix - dx < 0 || ix - dx >= nx || iy - dy < 0 || iy - dy >= ny) continue;
        const std::int64_t lo = std::max<std::int64_t>(first_iz, dz);
        const std::int64_t hi = std::min<std::int64_t>(end_iz, nz + dz);
        if (lo >= hi) continue;
        const std::int64_t n = row_node + lo;
        const double* from = tensions_of_row(row - dx - std::int64_t{nx} * dy) + o * nz + lo - dz;
        spring_rows::add_backward(hi - lo, from, at(n - delta[static_cast<std::size_t>(o)]), at(n),
                                  gx + lo, gy + lo, gz + lo);
      }
      for (std::size_t o = 0; o < 13; ++o) {  // springs to the nodes above
        const auto& [dx, dy, dz] = lattice::kForwardNeighbours[o];
        if (ix + dx < 0 || ix + dx >= nx || iy + dy < 0 || iy + dy >= ny) continue;
        const std::int64_t lo = std::max<std::int64_t>(first_iz, -dz);
        const std::int64_t hi = std::min<std::int64_t>(end_iz, nz - dz);
        if (lo >= hi) continue;
        const std::int64_t n = row_node + lo;
        spring_rows::subtract_forward(hi - lo, tension + o * nz + lo, at(n), at(n + delta[o]),
                                      gx + lo, gy + lo, gz + lo);
      }
      for (std::int64_t iz = first_iz; iz < end_iz; ++iz) {
        gradient(0, row_node + iz) = gx[iz];
        gradient(1, row_node + iz) = gy[iz];
        gradient(2, row_node + iz) = gz[iz];
      }
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
  for (std::size_t s = 0; s < sp.size(); ++s) {
    const Eigen::Matrix3d block = spring_block(sp, s, x);
    const std::int64_t i = sp.first[s];
    const std::int64_t j = sp.second(s);
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

// Every cell's gradient coefficients (eqs. 4.66-4.69, elastic::cell_value) are computed once
// and gathered by its eight vertices in CellStencil::gather's order, and the energy is summed
// in the blocks of detail::fixed_order_sums: bitwise the results of a pass over all cells into
// a scratch array (9 doubles per cell) and a gather, for any thread count, without that array.
// Cells are numbered layer by layer along z (cx + Cx (cy + Cy cz)), and the nodes of plane iz
// hold cells of layers iz - 1 and iz only. So each thread takes a contiguous run of the energy
// blocks, computes whole layers in order into two layer buffers (layer cz in buffer cz mod 2),
// and gathers plane iz once layer iz is done. It owns the planes whose first cell lies in its
// blocks (the last thread also the top plane, which starts no layer); it first computes the
// layer below its first plane, and its last layer may reach into the next thread's blocks; the
// energy counts only its own blocks.
// The work runs along x, one SIMD lane per cell or node (cell_rows.hpp): the two node planes
// of a layer are copied x fastest into three component arrays, the layer buffers hold each of
// the nine coefficients as an array over the layer's cells, and a node row gathers its cells
// one vertex offset at a time in the stencil's order, which every lane keeps.
ElasticValue VolumeKernel::evaluate_with_gradient(const lattice::Lattice& lat,
                                                  const Eigen::Matrix3Xd& x, double force_factor,
                                                  Eigen::Matrix3Xd& gradient) const {
  const auto cells = static_cast<std::int64_t>(lat.elements.size());
  if (cells == 0) return {0.0, 0.0};
  const double kappa = lat.polymer.kappa;
  const double v0 = std::pow(lat.element_length, 3);
  const int nx = lat.shape.nx();
  const int ny = lat.shape.ny();
  const int nz = lat.shape.nz();
  const std::int64_t row_cells = nx - 1;             // cells along x
  const std::int64_t layer = row_cells * (ny - 1);   // cells per layer
  const std::int64_t plane = std::int64_t{nx} * ny;  // nodes per plane
  const std::int64_t layers = cells / layer;         // nz - 1
  std::vector<std::array<double, 2>> partial = block_partials(cells);
  const bool parallel = cells >= detail::kParallelMinimum;
  const std::int64_t max_threads = parallel ? omp_get_max_threads() : 1;
  // Per thread: two node planes (3 components each), two coefficient layers (9 arrays each),
  // one cell row's energies and roundings, one node row's gradients.
  const std::int64_t scratch_per_thread = 2 * 3 * plane + 2 * 9 * layer + 2 * row_cells + 3 * nx;
  layer_buffers_.resize(static_cast<std::size_t>(max_threads * scratch_per_thread));

#pragma omp parallel if (parallel)
  {
    const auto threads = static_cast<std::int64_t>(omp_get_num_threads());
    const auto thread = static_cast<std::int64_t>(omp_get_thread_num());
    const ItemRange own = own_items(cells, thread, threads);
    // Planes [plane_begin, plane_end): those whose first cell (plane x layer) is in own.
    const std::int64_t plane_begin = (own.begin + layer - 1) / layer;
    const std::int64_t plane_end = thread + 1 == threads ? nz : (own.end + layer - 1) / layer;
    // Layers to compute: below the first plane, through the last plane's, and all own cells.
    const std::int64_t layer_begin =
        std::max<std::int64_t>(0, std::min(plane_begin - 1, own.begin / layer));
    const std::int64_t layer_end =
        std::min(layers, std::max(plane_end, own.end > own.begin ? (own.end - 1) / layer + 1 : 0));
    double* const planes = layer_buffers_.data() + thread * scratch_per_thread;
    double* const coefficients = planes + 2 * 3 * plane;
    double* const energy = coefficients + 2 * 9 * layer;
    double* const rounding = energy + row_cells;
    double* const gx = rounding + row_cells;
    double* const gy = gx + nx;
    double* const gz = gy + nx;
    const auto plane_of = [&](std::int64_t iz) { return planes + (iz & 1) * 3 * plane; };
    const auto layer_of = [&](std::int64_t cz) { return coefficients + (cz & 1) * 9 * layer; };
    const auto node_of = [&](std::int64_t ix, std::int64_t iy, std::int64_t iz) {
      return iz + nz * (ix + nx * iy);
    };
    const auto load_plane = [&](std::int64_t iz) {
      double* p = plane_of(iz);
      for (std::int64_t iy = 0; iy < ny; ++iy) {
        for (std::int64_t ix = 0; ix < nx; ++ix, ++p) {
          const std::int64_t n = node_of(ix, iy, iz);
          p[0] = x(0, n);
          p[plane] = x(1, n);
          p[2 * plane] = x(2, n);
        }
      }
    };
    OwnBlockSums sums(own, partial);
    const auto gather_plane = [&](std::int64_t iz) {
      for (std::int64_t iy = 0; iy < ny; ++iy) {
        for (std::int64_t ix = 0; ix < nx; ++ix) {
          const std::int64_t n = node_of(ix, iy, iz);
          gx[ix] = gradient(0, n);
          gy[ix] = gradient(1, n);
          gz[ix] = gradient(2, n);
        }
        for (const auto& [dx, dy, dz] : kCellsOfNode) {  // cell (ix - dx, iy - dy, iz - dz)
          const std::int64_t cy = iy - dy;
          const std::int64_t cz = iz - dz;
          if (cy < 0 || cy >= ny - 1 || cz < 0 || cz >= layers) continue;
          const double* const row = layer_of(cz) + row_cells * cy;
          cell_rows::Coefficients<const double*> t{};
          for (std::size_t k = 0; k < 9; ++k) t[k] = row + static_cast<std::int64_t>(k) * layer;
          // The node is local vertex 2 dx + 4 dy + dz: signs s_a, s_b, s_c by dx, dy, dz.
          cell_rows::add_vertex_gradient(row_cells, t, dx == 1 ? 1.0 : -1.0, dy == 1 ? 1.0 : -1.0,
                                         dz == 1 ? 1.0 : -1.0, gx + dx, gy + dx, gz + dx);
        }
        for (std::int64_t ix = 0; ix < nx; ++ix) {
          const std::int64_t n = node_of(ix, iy, iz);
          gradient(0, n) = gx[ix];
          gradient(1, n) = gy[ix];
          gradient(2, n) = gz[ix];
        }
      }
    };
    if (layer_begin < layer_end) load_plane(layer_begin);
    for (std::int64_t cz = layer_begin; cz < layer_end; ++cz) {
      load_plane(cz + 1);
      for (std::int64_t cy = 0; cy < ny - 1; ++cy) {
        cell_rows::Corners corners{};
        for (std::size_t v = 0; v < 8; ++v) {  // local vertex v = 2 dx + 4 dy + dz
          const std::int64_t dx = (v >> 1U) & 1U;
          const std::int64_t dy = (v >> 2U) & 1U;
          const std::int64_t dz = v & 1U;
          const double* p = plane_of(cz + dz) + nx * (cy + dy) + dx;
          corners.x[v] = p;
          corners.y[v] = p + plane;
          corners.z[v] = p + 2 * plane;
        }
        cell_rows::Coefficients<double*> t{};
        double* const row = layer_of(cz) + row_cells * cy;
        for (std::size_t k = 0; k < 9; ++k) t[k] = row + static_cast<std::int64_t>(k) * layer;
        cell_rows::coefficients(row_cells, corners, kappa, v0, force_factor, t, energy, rounding);
        const std::int64_t first_cell = cz * layer + row_cells * cy;
        for (std::int64_t i = 0; i < row_cells; ++i) {
          sums.add(first_cell + i, energy[i], rounding[i]);
        }
      }
      if (cz >= plane_begin && cz < plane_end) gather_plane(cz);
    }
    // The top plane holds cells of the last layer only.
    if (plane_end == nz && plane_begin <= nz - 1) gather_plane(nz - 1);
  }
  return total_of(partial);
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
  for (const auto& element : lat.elements) {
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
