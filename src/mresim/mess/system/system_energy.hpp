#pragma once

// The assembled 3D system (Chapter 4, MESS): lattice, profile, magnetic model and applied field,
// current node positions and particle magnetizations, boundary constraints; its energy broken
// down by term and its gradient with respect to the node positions (SI units throughout).
//
// Energy (Section 4.2.4): a list of energy terms (terms/energy_term.hpp), in registry order;
// the built-in ones, always present, are
//   springs  eq. 4.62                      volume  eq. 4.64 x l_e^3 (elastic_terms.hpp)
//   Zeeman   eq. 4.70                      dipole  eq. 4.71
//   self     eq. 4.76 (in the total; + mu0 V |M|^2/6 with demagnetization)
//   self_linearized  eq. 4.73 (reported only, for comparison with the dissertation's plots)
//   WCA      eq. 4.79                      load    -sum_n f_n . (x_n - x_n^0) (applied forces)
// total = springs + volume + zeeman + dipole + self + wca + load, plus the optional terms the
// run file chose ([terms.<name>] tables).
//
// Forces. The magnetic terms depend on the particle centres c_p; their gradient with respect to
// c_p at fixed M (dipole, eq. 4.78, plus WCA, eq. 4.80; Zeeman and self have none in a uniform
// field) is the total derivative at the self-consistent M by the envelope theorem
// (docs/magnetization-3d.md). It is shared equally by the particle's n_p nodes (Section 4.2.4,
// "distributed among all nodes ... to ensure rigid body translation"):
//   dE/dx_i += (dE/dc_p) / n_p   for every node i of particle p.
// With CentreRule::all_nodes (physical profile) c_p is the mean of all n_p nodes, so this is the
// exact gradient. With CentreRule::centre_voxel (seed profile: the original's centre, the mean of
// the 8 corners of the centre voxel, docs/original-code.md#particles) the spreading is the
// original's and not the exact gradient of E(c_p(x)); the two centres differ only by the
// particle's internal deformation (particle springs are 1e4 times stiffer than the polymer's).
//
// "Potential" = the function whose gradient the forces are: total + sum over the terms of
// (force_factor - 1) E_t, i.e. total + (volume_force_factor - 1) volume, the total for the physical
// profile and springs + 4 x volume + ... for the seed profile
// (docs/original-code.md#volume-elements). The minimisers minimise the potential; every report uses
// the energies.
//
// Magnetization. The magnetizations are part of the state. evaluate() re-solves them
// (solve_magnetization with the current M as history, the fallback chain of
// docs/magnetization-3d.md) according to MagnetizationUpdate: before every evaluation (the
// original's dynamics), only once a particle centre has moved more than resolve_distance l_e
// since the last solve, or only when asked (solve_magnetization()). Every solve is recorded
// (MagnetizationStats); an unconverged solve is counted, never hidden.

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "mresim/mess/lattice/lattice.hpp"
#include "mresim/mess/magnetization/self_consistent.hpp"
#include "mresim/mess/system/constraints.hpp"
#include "mresim/mess/system/mess_energies.hpp"
#include "mresim/mess/system/mess_settings.hpp"
#include "mresim/mess/terms/energy_term.hpp"

namespace mresim::mess {

struct ModelProfile;  // profile/model_profile.hpp

struct Evaluation {
  MessEnergies energies;
  double potential = 0.0;  // total + sum_t (force_factor_t - 1) E_t
  // The potential's rounding error is about machine epsilon times this: the sum of the
  // absolute values of its terms plus the terms' cancellation scales (TermValue::rounding),
  // each times its force factor. Used by line searches.
  double magnitude = 0.0;
};

struct MagnetizationStats {
  std::int64_t solves = 0;
  std::int64_t unconverged = 0;             // solves that missed the tolerance
  std::int64_t total_iterations = 0;        // over all solves and methods
  std::array<std::int64_t, 3> by_method{};  // solves ended by fixed_point, anderson, newton
  magnetism::MagnetizationResult last;      // the latest solve's full diagnostics
};

// The energies, potential and magnitude of one evaluation from every term's value (in list
// order, reported-only terms included): MessSystem::evaluate's bookkeeping, shared with the
// distributed evaluation (distributed/distributed_system.hpp). `state` gives the force factors.
Evaluation evaluation_from_terms(const std::vector<std::unique_ptr<EnergyTerm>>& terms,
                                 const std::shared_ptr<const TermLabels>& labels,
                                 const std::vector<TermValue>& values, const TermState& state);

class MessSystem {
 public:
  // Throws std::invalid_argument if the model's particle radius is not the lattice's or the
  // settings are invalid. Positions start at the lattice's initial positions, M at zero with
  // no history (the first solve starts from FK(H_ext)), no constraints, no applied forces.
  // `terms`: the optional energy terms (run file [terms.<name>], read_term_tables()); the
  // always-present ones are added by the registry.
  MessSystem(lattice::Lattice lattice, magnetism::MagneticModel model, MessSettings settings,
             std::vector<TermSpec> terms = {});
  // Copies rebuild their terms (terms keep scratch arrays that copies must not share).
  MessSystem(const MessSystem& other);
  MessSystem& operator=(const MessSystem& other);
  MessSystem(MessSystem&&) noexcept = default;
  MessSystem& operator=(MessSystem&&) noexcept = default;
  ~MessSystem() = default;

  // The dissertation's particles (chi0 = 70, Ms = 1.6e6 A/m) with the lattice's radius, WCA
  // scaled by the profile's Ms, the profile's settings. applied_field is H_ext in A/m.
  static MessSystem make(lattice::Lattice lattice, const Eigen::Vector3d& applied_field,
                         const ModelProfile& profile,
                         const magnetism::MagneticParticles& particles = {},
                         std::vector<TermSpec> terms = {});

  // The energy terms, in list order, and their labels (every MessEnergies of this system
  // shares them).
  const std::vector<std::unique_ptr<EnergyTerm>>& terms() const { return terms_; }
  const std::shared_ptr<const TermLabels>& energy_labels() const { return labels_; }

  const lattice::Lattice& lattice() const { return lattice_; }
  const magnetism::MagneticModel& model() const { return model_; }
  const MessSettings& settings() const { return settings_; }
  MessSettings& settings() { return settings_; }
  std::int64_t node_count() const { return lattice_.node_count(); }
  std::size_t particle_count() const { return lattice_.particle_count(); }
  double length_scale() const { return lattice_.element_length; }

  // H_ext (A/m). The next evaluation re-solves M (unless the update is manual).
  void set_applied_field(const Eigen::Vector3d& applied_field);

  const Eigen::Matrix3Xd& positions() const { return positions_; }
  // All node positions (m); the held coordinates are then written from the constraints.
  void set_positions(const Eigen::Matrix3Xd& positions);
  // The same, taking the array over instead of copying it.
  void set_positions(Eigen::Matrix3Xd&& positions);
  // Mutable access for solvers; call apply_constraints() if held coordinates may have changed.
  Eigen::Matrix3Xd& mutable_positions() { return positions_; }

  const BoundaryConstraints& constraints() const { return constraints_; }
  // Validates, stores and applies (held coordinates are written into the positions).
  void set_constraints(BoundaryConstraints constraints);
  void apply_constraints() { constraints_.apply(positions_); }

  // Applied nodal forces (N, 3 x N; an empty matrix removes them). Their potential energy,
  // -sum f.(x - x0) with x0 the lattice's initial positions, is the 'load' term.
  void set_applied_forces(const Eigen::Matrix3Xd& forces);
  const Eigen::Matrix3Xd& applied_forces() const { return applied_forces_; }

  const Eigen::Matrix3Xd& magnetizations() const { return M_; }
  // Sets M (A/m, 3 x N_p) as the history for the next solve.
  void set_magnetizations(const Eigen::Matrix3Xd& M);
  bool has_magnetization_history() const { return has_history_; }

  // Particle centres under the settings' CentreRule (m, 3 x N_p).
  Eigen::Matrix3Xd particle_centres() const;
  // Either rule, e.g. to compare (or the bounding-box midpoint the original's analysis uses).
  Eigen::Matrix3Xd particle_centres(CentreRule rule) const;
  // The centres under `rule` at other positions of this lattice (3 x N, m).
  Eigen::Matrix3Xd particle_centres_at(const Eigen::Matrix3Xd& x, CentreRule rule) const;
  Eigen::Matrix3Xd particle_bounding_box_centres() const;

  // Re-solves M now at the current positions from the current M (history).
  const magnetism::MagnetizationResult& solve_magnetization();
  // The same at the given particle centres (3 x N_p, m) instead of those of positions(): for an
  // evaluation whose positions live elsewhere (distributed/distributed_system.hpp).
  const magnetism::MagnetizationResult& solve_magnetization_at(const Eigen::Matrix3Xd& centres);
  // evaluate()'s update rule for M (settings().magnetization_update) at the given centres.
  void update_magnetization_at(const Eigen::Matrix3Xd& centres);
  const MagnetizationStats& magnetization_stats() const { return stats_; }

  // Energies at the current positions and M (no re-solve).
  MessEnergies energies() const;
  // Re-solves M per the update rule, then energies, potential and (if not null) the gradient
  // of the potential with respect to every node coordinate (J/m, 3 x N; held coordinates are
  // not zeroed, see BoundaryConstraints / DofMap).
  Evaluation evaluate(Eigen::Matrix3Xd* gradient);
  // Gradient of the terms with respect to the particle centres at the current M (J/m,
  // 3 x N_p): dipole + WCA for the built-in terms.
  Eigen::Matrix3Xd centre_gradient() const;

  // Hessian-vector products and the sparse elastic Hessian, at the current positions and M
  // (no re-solve), for Newton-type solvers. Both are of the potential, at fixed M.
  //
  // H v for a node direction v (3 x N, m): the elastic terms exactly; the centre terms with
  // the centre rule: v_c = the mean of v over the nodes that define c_p, and the product
  // (dE/dc)' v_c spread as 1/n_p to each of the particle's nodes, i.e. the derivative of
  // evaluate()'s gradient at fixed M. (With CentreRule::centre_voxel that map is not
  // symmetric, as the gradient is not exact; see above.) Bitwise independent of the thread
  // count for the elastic terms and WCA; the dipole term uses central differences
  // (terms/magnetic_terms.cpp).
  Eigen::Matrix3Xd hessian_product(const Eigen::Matrix3Xd& v) const;
  // The Hessian of the terms that have sparse entries (springs and volume, times their force
  // factors), 3N x 3N with row/column 3 n + a; held coordinates are not removed.
  Eigen::SparseMatrix<double> elastic_hessian() const;
  // The same Hessian into any sink (e.g. a preallocated pattern, solvers/hessian_assembly.hpp).
  void add_elastic_hessian_blocks(HessianBlockSink& sink) const;
  // The same at other positions of this lattice (3 x N, m; e.g. where a preconditioner kept
  // from an earlier state was built). std::invalid_argument if the shape differs.
  void add_elastic_hessian_blocks(HessianBlockSink& sink, const Eigen::Matrix3Xd& at) const;
  // elastic_hessian() v without assembling it (J/m^2 x m; 3 x N), bitwise independent of the
  // thread count.
  Eigen::Matrix3Xd elastic_hessian_product(const Eigen::Matrix3Xd& v) const;

  // The Hessian of the reduced energy E(x, M(x)) with respect to the particle centres
  // (3 N_p x 3 N_p, J/m^2, row/column 3 p + a), of the terms that depend on the centres
  // (dipole, WCA and the optional centre terms): central differences of their centre gradient
  // with M re-solved, from the current M, at each shifted set of centres. By the envelope
  // theorem that gradient is the reduced energy's, so this includes how M follows the
  // centres, which hessian_product() (fixed M) leaves out. The solves use a tolerance near
  // machine precision (whatever the settings say), so that the differences are not noise;
  // step = 1e-4 l_e. Symmetrised. The system's state and statistics are not changed.
  Eigen::MatrixXd reduced_centre_hessian() const;

 private:
  void maybe_update_magnetization();
  void build_terms();
  // Runs f(state) with the state at the current positions, centres and M.
  template <class F>
  auto with_state(F&& f) const;
  // The same at positions `x` (3 x N) and their centres.
  template <class F>
  auto with_state_at(const Eigen::Matrix3Xd& x, F&& f) const;

  lattice::Lattice lattice_;
  magnetism::MagneticModel model_;  // self_energy forced to consistent (4.76)
  MessSettings settings_;
  std::vector<TermSpec> term_specs_;
  std::vector<std::unique_ptr<EnergyTerm>> terms_;
  std::shared_ptr<const TermLabels> labels_;
  Eigen::Matrix3Xd positions_;
  BoundaryConstraints constraints_;
  Eigen::Matrix3Xd applied_forces_;
  Eigen::Matrix3Xd M_;
  bool has_history_ = false;
  bool field_changed_ = true;
  Eigen::Matrix3Xd last_solve_centres_;
  MagnetizationStats stats_;
};

}  // namespace mresim::mess
