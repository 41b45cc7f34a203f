#pragma once

// Elastic energy terms of the 3D model (Section 4.2.4) with their gradients with respect to the
// node positions (SI: positions in m, energies in J, gradients dE/dx in J/m = N; the force on a
// node is minus its gradient column).
//
//   springs  eq. 4.62  U = 1/2 sum_s k_s (|x_j - x_i| - L_s)^2
//            eq. 4.63  dU/dx_j = -dU/dx_i = k_s (|r| - L_s) r/|r|,  r = x_j - x_i
//   volume   eq. 4.64 as an energy (the printed equation is a density: times V0 = l_e^3)
//            U = 1/2 kappa V0 sum_cells (V/V0 - 1)^2,  V = a . (b x c)  (eq. 4.48)
//            dU/dx_v = kappa (V/V0 - 1) dV/dx_v, with dV/dx_v from
//            lattice::cell_volume_and_gradient: eqs. 4.66-4.69 *with* the 1/4 that comes from
//            averaging four edge vectors into a, b, c (the printed equations omit it).
//
// Profiles (docs/model-profiles.md, docs/original-code.md#volume-elements): the original code's
// volume forces are 4 times the gradient of the energy it reports (its kernels use eqs. 4.66-4.69
// without the 1/4). ElasticTermSettings::volume_force_factor carries that factor: 1 for the
// physical profile (forces are the exact gradient), 4 for the seed profile. The *reported* volume
// energy is always the one above (kappa, not 4 kappa); the function whose gradient the seed's
// forces are is springs + volume_force_factor * volume (the "potential", see system_energy.hpp).

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <array>
#include <cstdint>
#include <vector>

#include "mresim/mess/lattice/lattice.hpp"
#include "mresim/mess/terms/grid_stencil.hpp"
#include "mresim/mess/terms/hessian_blocks.hpp"

namespace mresim::mess {

struct ElasticTermSettings {
  // Multiplier of the exact volume-term gradient in the forces: 1 = exact (physical profile);
  // 4 = the original code's forces (seed profile), i.e. a volume stiffness of 4 kappa in the
  // dynamics while energies are reported with kappa.
  double volume_force_factor = 1.0;
};

// ---------------------------------------------------------------- serial reference formulas

// Eq. 4.62 over all springs of the set.
double spring_energy(const lattice::SpringSet& springs, const Eigen::Matrix3Xd& x);
// Adds the exact gradient of eq. 4.62 (eq. 4.63 with the sign of a gradient) to `gradient`.
void add_spring_gradient(const lattice::SpringSet& springs, const Eigen::Matrix3Xd& x,
                         Eigen::Matrix3Xd& gradient);

// Eq. 4.64 times V0 = l_e^3, summed over `elements` (kappa in Pa, l_e in m).
double volume_energy(const lattice::GridCells& elements, double kappa, double element_length,
                     const Eigen::Matrix3Xd& x);
// Adds force_factor times the exact gradient of volume_energy (eqs. 4.65-4.69 with the 1/4).
void add_volume_gradient(const lattice::GridCells& elements, double kappa, double element_length,
                         const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& gradient,
                         double force_factor = 1.0);

// ------------------------------------------------ the parallel evaluator used by the solvers

struct ElasticEnergies {
  double springs = 0.0;  // J, eq. 4.62
  double volume = 0.0;   // J, eq. 4.64 x l_e^3 (always with kappa, whatever the force factor)
  // Size of each sum's rounding error divided by machine epsilon: sum k |l - L| l over the
  // springs and sum kappa V0 |V/V0 - 1| over the cells. The stretch l - L and the volume
  // change are differences of nearly equal numbers, so at small strain an energy is only known
  // to about eps times these, far worse than eps times the energy itself (line searches need
  // to know).
  double springs_rounding = 0.0;
  double volume_rounding = 0.0;
};

// The two elastic kernels, parallelised with OpenMP so that every result is bitwise
// independent of the thread count: every spring's tension and every cell's volume derivative
// is computed once, then every node gathers its own contributions in a fixed order (increasing
// spring or cell index, found by the grid stencils of grid_stencil.hpp). Neither keeps an array
// over all springs or cells: each thread sweeps its share in index order into a small buffer
// (the springs' tensions in a ring, the cells' derivatives in two layers) and gathers the nodes
// whose contributions are all there (SpringKernel and VolumeKernel::evaluate_with_gradient).
// Energies are summed in fixed blocks (fixed_order.hpp). Gradients and Hessian products are ADDED
// per node in the order g = out.col(n); g += contributions; out.col(n) = g, so a springs pass
// followed by a volume pass gives the same bits as one fused pass. Not safe for concurrent calls on
// one object (the scratch arrays are shared); copies are independent. `lattice` must be the one
// given to the constructor.

struct ElasticValue {
  double energy = 0.0;    // J
  double rounding = 0.0;  // see ElasticEnergies
};

// Springs, eq. 4.62, and its exact Hessian: per spring the 3 x 3 block
// B = k [(1 - L/l) I + (L/l) r^ r^T] (r = x_j - x_i, l = |r|), with H_jj = H_ii = B and
// H_ij = H_ji = -B.
class SpringKernel {
 public:
  SpringKernel() = default;
  explicit SpringKernel(const lattice::Lattice& lattice);

  // Energy; adds the gradient to `gradient` (3 x N) if not null.
  ElasticValue evaluate(const lattice::Lattice& lattice, const Eigen::Matrix3Xd& x,
                        Eigen::Matrix3Xd* gradient) const;
  // out += H v (all 3 x N).
  void add_hessian_product(const lattice::Lattice& lattice, const Eigen::Matrix3Xd& x,
                           const Eigen::Matrix3Xd& v, Eigen::Matrix3Xd& out) const;
  // Four blocks per spring (B at (i, i) and (j, j), -B at (i, j) and (j, i)), in spring order.
  static void add_hessian_blocks(const lattice::Lattice& lattice, const Eigen::Matrix3Xd& x,
                                 HessianBlockSink& sink);
  // The same as triplets: 36 entries per spring, rows/columns 3 n + a.
  static void add_hessian_entries(const lattice::Lattice& lattice, const Eigen::Matrix3Xd& x,
                                  std::vector<Eigen::Triplet<double>>& entries);

 private:
  // evaluate with a gradient: the fused tension sweep and gather.
  ElasticValue evaluate_with_gradient(const lattice::Lattice& lattice, const Eigen::Matrix3Xd& x,
                                      Eigen::Matrix3Xd& gradient) const;

  std::int64_t node_count_ = 0;
  SpringStencil stencil_;  // node -> incident springs, from the grid
  // Scratch of the Hessian product: B (v_j - v_i) per spring (3 doubles).
  mutable std::vector<double> scratch_;
  // Node n's spring along forward offset o as an index into stiffness_table_, at o N + n
  // (0 where the offset leaves the box): a row of nodes reads one offset's contiguously.
  std::vector<std::uint8_t> stiffness_index_;
  std::vector<double> stiffness_table_;  // N/m, the lattice's distinct spring stiffnesses
  // evaluate_with_gradient's scratch: the positions as three component arrays (3 N), and per
  // thread a ring of the last nx + 2 rows' tensions with one row's energies and gradients.
  mutable std::vector<double> components_;
  mutable std::vector<double> row_scratch_;
};

// Volume elements, eq. 4.64 x V0, times force_factor in gradients and Hessians. Exact Hessian
// of U = 1/2 kappa V0 (V/V0 - 1)^2 per cell:
//   H v = kappa/V0 (dV/dx . v) dV/dx + kappa (V/V0 - 1) d(dV/dx)[v],
// V = a . (b x c) with the averaged edge vectors (the 1/4 included), so that
// d(dV/dx_k)[v] = (s_a (db x c + b x dc) + s_b (dc x a + c x da) + s_c (da x b + a x db)) / 4,
// da, db, dc the averaged edge vectors of v.
class VolumeKernel {
 public:
  VolumeKernel() = default;
  explicit VolumeKernel(const lattice::Lattice& lattice);

  ElasticValue evaluate(const lattice::Lattice& lattice, const Eigen::Matrix3Xd& x,
                        double force_factor, Eigen::Matrix3Xd* gradient) const;
  void add_hessian_product(const lattice::Lattice& lattice, const Eigen::Matrix3Xd& x,
                           double force_factor, const Eigen::Matrix3Xd& v,
                           Eigen::Matrix3Xd& out) const;
  // 64 blocks per cell (its dense 24 x 24 block), in cell order.
  static void add_hessian_blocks(const lattice::Lattice& lattice, const Eigen::Matrix3Xd& x,
                                 double force_factor, HessianBlockSink& sink);
  // The same as triplets: 576 entries per cell.
  static void add_hessian_entries(const lattice::Lattice& lattice, const Eigen::Matrix3Xd& x,
                                  double force_factor,
                                  std::vector<Eigen::Triplet<double>>& entries);

 private:
  // Node gather of per-cell vectors t (9 per cell: the s_a, s_b, s_c coefficients).
  void gather(const std::vector<double>& terms, Eigen::Matrix3Xd& out) const;
  // evaluate with a gradient: cells layer by layer, each node plane gathered from two layers.
  ElasticValue evaluate_with_gradient(const lattice::Lattice& lattice, const Eigen::Matrix3Xd& x,
                                      double force_factor, Eigen::Matrix3Xd& gradient) const;

  std::int64_t node_count_ = 0;
  CellStencil stencil_;  // node -> the cells holding it, from the grid
  // Scratch of the Hessian product: per cell the three vectors t_a, t_b, t_c (see gather).
  mutable std::vector<double> scratch_;
  // evaluate_with_gradient's scratch per thread: two node planes, two layers of cell
  // coefficients, a layer's energies and a node line's gradients; and every cell's energy and
  // rounding, in cell order (16 bytes per cell).
  mutable std::vector<double> layer_buffers_;
  mutable std::vector<std::array<double, 2>> cell_energies_;
};

// Both kernels, as one evaluator of springs + volume (used by tests and benchmarks; the
// system evaluates them as two terms, terms/elastic_term_types.cpp).
class ElasticTerms {
 public:
  ElasticTerms() = default;
  ElasticTerms(const lattice::Lattice& lattice, ElasticTermSettings settings);

  const ElasticTermSettings& settings() const { return settings_; }
  void set_settings(const ElasticTermSettings& settings) { settings_ = settings; }

  // Energies at x (3 x N, m). If `gradient` is not null it is overwritten with
  // d(springs)/dx + volume_force_factor d(volume)/dx (J/m).
  ElasticEnergies evaluate(const lattice::Lattice& lattice, const Eigen::Matrix3Xd& x,
                           Eigen::Matrix3Xd* gradient) const;

 private:
  ElasticTermSettings settings_;
  SpringKernel springs_;
  VolumeKernel volume_;
};

}  // namespace mresim::mess
