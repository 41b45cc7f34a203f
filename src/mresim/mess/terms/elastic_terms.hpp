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
#include <array>
#include <cstdint>
#include <vector>

#include "mresim/mess/lattice/lattice.hpp"

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
double volume_energy(const std::vector<std::array<std::int32_t, 8>>& elements, double kappa,
                     double element_length, const Eigen::Matrix3Xd& x);
// Adds force_factor times the exact gradient of volume_energy (eqs. 4.65-4.69 with the 1/4).
void add_volume_gradient(const std::vector<std::array<std::int32_t, 8>>& elements, double kappa,
                         double element_length, const Eigen::Matrix3Xd& x,
                         Eigen::Matrix3Xd& gradient, double force_factor = 1.0);

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

// Energies and gradient of both terms for one lattice, parallelised with OpenMP so that the
// result is bitwise independent of the thread count: every spring's tension and every cell's
// volume derivative is computed once into scratch arrays, then every node gathers its own
// contributions in a fixed order (node -> incident springs and cells, built once). Energies are
// summed in fixed blocks (fixed_order.hpp). Not safe for concurrent calls on one object (the
// scratch arrays are shared); copies are independent.
class ElasticTerms {
 public:
  ElasticTerms() = default;
  ElasticTerms(const lattice::Lattice& lattice, ElasticTermSettings settings);

  const ElasticTermSettings& settings() const { return settings_; }
  void set_settings(const ElasticTermSettings& settings) { settings_ = settings; }

  // Energies at x (3 x N, m). If `gradient` is not null it is overwritten with
  // d(springs)/dx + volume_force_factor d(volume)/dx (J/m). `lattice` must be the one given to
  // the constructor.
  ElasticEnergies evaluate(const lattice::Lattice& lattice, const Eigen::Matrix3Xd& x,
                           Eigen::Matrix3Xd* gradient) const;

 private:
  ElasticTermSettings settings_;
  std::int64_t node_count_ = 0;
  // Node -> incident springs: entries 2 s + (node is the spring's second end).
  std::vector<std::int64_t> spring_offsets_;
  std::vector<std::int32_t> spring_entries_;
  // Node -> incident cells: entries 8 c + v (v = the node's local vertex in cell c).
  std::vector<std::int64_t> cell_offsets_;
  std::vector<std::int32_t> cell_entries_;
  // Scratch: tension k (l - L)/l per spring; per cell the three vectors
  // f (b x c), f (c x a), f (a x b) with f = factor kappa (V/V0 - 1) / 4.
  mutable std::vector<double> tension_;
  mutable std::vector<double> cell_terms_;
};

}  // namespace mresim::mess
