#pragma once

// The run file of the 3D model (MESS, Chapter 4): reading, validating and describing it.
//
// The four run types of the 3D model ([run] type = "mess_hysteresis", "mess_strain",
// "mess_magnetostriction", "mess_stress") share one schema, documented key by key in
// docs/run-files-3d.md. This module turns a run file into a plain MessSpec that holds every
// parameter those run types need, already validated, and describes it for `mresim info`
// without relaxing anything. It registers no run type: the run types (with the solvers of
// src/mresim/mess/) call
//
//   MessSpec spec = read_mess_spec(root, settings.type);   // in their PlanFactory
//   describe_mess(spec, report);                           // in RunPlan::describe
//   lattice::Lattice lat = lattice::build_lattice(spec.lattice);   // in execute()
//
// Everything is SI (m, Pa, A/m, T, kg) except where a key says otherwise (angles in degrees
// in the file, stored in radians where noted; leapfrog settings in the seed's scaled units).

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "mresim/app/info_report.hpp"
#include "mresim/config/table_reader.hpp"
#include "mresim/mess/lattice/lattice.hpp"
#include "mresim/mess/magnetization/magnetic_particles.hpp"
#include "mresim/mess/magnetization/self_consistent.hpp"
#include "mresim/mess/profile/model_profile.hpp"
#include "mresim/mess/solvers/contact_gap.hpp"
#include "mresim/mess/solvers/node_scaling.hpp"
#include "mresim/mess/terms/energy_term.hpp"
#include "mresim/mess/terms/magnetic_energy.hpp"

namespace mresim::mess_protocol {
class Protocol;
}  // namespace mresim::mess_protocol

namespace mresim::mess_config {

// ---------------------------------------------------------------------------------------------
// Run types

// The 3D run types are the registered protocols (protocols/protocol.hpp): one per
// src/mresim/mess/protocols/*_protocol.cpp. Their names, sorted ("mess_hysteresis", ...).
std::vector<std::string> mess_run_type_names();

// ---------------------------------------------------------------------------------------------
// [field]: the sequence of applied fields

// How the magnitudes list becomes the applied sequence.
enum class FieldSequence {
  loop,  // u, reversed u, -u, reversed -u, u: 5 (n - 1) + 1 fields
         // (docs/original-code.md#field-sequences)
  up,    // u as given
};

struct FieldSpec {
  enum class Form { max_and_steps, magnitudes, vectors };
  Form form = Form::max_and_steps;
  // Forms max_and_steps and magnitudes: the upward list u (T) and the direction.
  std::vector<double> magnitudes;  // T; max_and_steps: 0, max/steps, ..., max
  double max = 0.0;                // T (the largest magnitude of u; of |B| for vectors)
  long steps = 0;                  // max_and_steps only
  double theta_deg = 0.0;          // polar angle from +z
  double phi_deg = 0.0;            // azimuth from +x
  FieldSequence sequence = FieldSequence::loop;
  // The applied fields B_ext = mu0 H_ext in tesla, in the order they are applied (for
  // mess_strain and mess_stress: the inner loop, repeated at every strain or stress value).
  std::vector<Eigen::Vector3d> values;
};

// The applied sequence of a loop over u (u[0] must be 0): u, u reversed without its last, -u
// without its first, -u reversed without its last, u without its first.
std::vector<double> hysteresis_loop(const std::vector<double>& up);
// B (sin theta cos phi, sin theta sin phi, cos theta), angles in degrees.
Eigen::Vector3d field_vector(double magnitude, double theta_deg, double phi_deg);

// ---------------------------------------------------------------------------------------------
// [strain] (mess_strain) and [stress] (mess_stress)

enum class LoadKind { shear, tension, compression, torsion };
std::string to_string(LoadKind kind);

// Which surfaces a shear strain holds (docs/original-code.md#boundary-conditions).
enum class ShearBoundary {
  all_faces,     // every surface node follows u = h tan(gamma) (the original's
                 // strain_simple_shearing; the dissertation's simple shear, eq. 4.96)
  normal_faces,  // only the two faces normal to `normal` are held, the lower one fixed, the
                 // upper one displaced by L tan(gamma); the side faces are free (strain_shearing)
};

struct StrainSpec {
  LoadKind kind = LoadKind::shear;
  int normal = 2;     // axis of the surface normal (0 = x, 1 = y, 2 = z): the loaded faces
  int direction = 0;  // shear: displacement axis (!= normal); otherwise equal to normal
  ShearBoundary boundary = ShearBoundary::all_faces;  // shear only
  // Applied values, first 0: shear angle gamma (rad, u = h tan gamma); tension and compression
  // the engineering strain along `normal` (compression stored negative); torsion the twist of
  // the upper face about the box's axis along `normal` (rad, right-handed about +normal).
  std::vector<double> values;
};

// Where a stress is applied (docs/original-code.md#boundary-conditions).
enum class StressLoading {
  one_face,    // lower face fixed, traction on the upper face (simple_stress_*)
  both_faces,  // opposite tractions on both faces, nothing fixed (special_stress_*); shear also
               // loads the pair of faces normal to `direction`, along `normal`
};

struct StressSpec {
  LoadKind kind = LoadKind::shear;  // shear, tension or compression
  int normal = 2;
  int direction = 0;
  StressLoading loading = StressLoading::one_face;
  // Pa, first 0; tension positive, compression stored negative, shear signed along direction.
  std::vector<double> values;
};

// ---------------------------------------------------------------------------------------------
// [solver] and [output]

// [solver] method: "lbfgs" (also spelt "minimiser", the default), "newton" (Newton-Krylov with
// algebraic multigrid, for large lattices: docs/mess-solvers.md) or "leapfrog" (the seed's
// damped dynamics).
// minimiser: L-BFGS with the multilevel preconditioner (the default); lbfgs: L-BFGS with the
// rigid-particle preconditioner alone (the method before the multilevel one, kept to measure
// against); newton: Newton-Krylov; leapfrog: the original's damped leapfrog.
enum class SolverMethod { minimiser, lbfgs, newton, leapfrog };

// The run file's spelling of `method` ("minimiser", "lbfgs", "newton", "leapfrog").
constexpr const char* solver_method_name(SolverMethod method) {
  switch (method) {
    case SolverMethod::lbfgs:
      return "lbfgs";
    case SolverMethod::newton:
      return "newton";
    case SolverMethod::leapfrog:
      return "leapfrog";
    case SolverMethod::minimiser:
      break;
  }
  return "minimiser";
}

struct MinimiserSettings {
  // Converged when the largest net force on a free node is below force_tolerance * k_eff l_e
  // (the characteristic force of the seed's scaling,
  // docs/original-code.md#lengths-spring-constants-and-scaling).
  double force_tolerance = 1e-6;
  long max_iterations = 100000;
};

// The seed's damped leapfrog (docs/original-code.md#time-integration, #convergence), in its scaled
// units.
struct LeapfrogSettings {
  double dt = 5e-3;             // units of t_c
  long steps_per_round = 5000;  // time steps between convergence checks
  long max_rounds = 40;         // integration rounds per field/strain step
  double drag = 1.0;            // units of 1/t_c
};

// The seed profile's leapfrog stability limit dt < 2/omega_max in units of t_c for
// discretization orders 2-5 (4.8e-3, 5.6e-3, 5.7e-3, 5.8e-3); std::nullopt for other orders,
// where it is not known. The reader refuses leapfrog.dt at or above it (seed profile only).
std::optional<double> leapfrog_stability_limit(int discretization_order);

// Where a loaded step of a strain run starts (protocols/load_step_start.hpp): from a
// prediction (the strain secant or the previous field's response, each also corrected by the
// previous fields: extrapolated), from the prediction without those corrections (secant, the
// default before them, kept to measure against), or from the previous load value's state as it
// is (previous, the original code).
enum class LoadStepStart { extrapolated, secant, previous };

// Where a field step (every step of a field loop or series; the zero-load steps of strain and
// stress runs) from the third field on starts (protocols/load_step_start.hpp): from the secant
// through the two previous fields' results, or from the previous field's result as it is (the
// original code).
enum class FieldStepStart { extrapolated, previous };

struct SolverSpec {
  SolverMethod method = SolverMethod::minimiser;
  // Default: extrapolated, except with the leapfrog (which reproduces the original: previous).
  LoadStepStart load_step_start = LoadStepStart::extrapolated;
  // Default: extrapolated, except with the leapfrog (previous).
  FieldStepStart field_step_start = FieldStepStart::extrapolated;
  // method = "minimiser" only: how its multilevel preconditioner (from 40,000 nodes) scales the
  // polymer's nodes (solvers/node_scaling.hpp).
  mess::NodeScaling node_scaling = mess::NodeScaling::blocks;
  // method = "minimiser" only: whether that preconditioner solves the polymer between particles
  // in contact exactly (solvers/contact_gap_blocks.hpp).
  mess::ContactGap contact_gap = mess::ContactGap::exact;
  // method = "minimiser" only: the largest node displacement (lattice spacings) from the state
  // that preconditioner was built at up to which a step keeps it (solvers/preconditioner_cache
  // .hpp); 0: built at every step's start. 0.3: measured on the full-size helix and Fig. 4.11
  // loop (docs/performance.md, "Routes measured for the helix's remaining 1.7x").
  double preconditioner_reuse = 0.3;
  MinimiserSettings minimiser;
  LeapfrogSettings leapfrog;
  // atol, rtol, iteration budgets; `demagnetization` mirrors MessSpec::demagnetization.
  magnetism::MagnetizationOptions magnetization;
};

// [analysis]: settings of what is derived from the relaxed states (docs/run-files-3d.md).
struct AnalysisSpec {
  // Two particles whose centres are at most this far apart (m) are in contact for the cluster
  // analysis (/steps/cluster_count, largest_cluster, cluster_id). Resolved while reading: the
  // run file's `cluster_distance`, else the WCA cut-off 2^(1/6)(2R + 100 nm) (eq. 4.79), the
  // distance below which the particles repel.
  double cluster_distance = 0.0;
  bool cluster_distance_given = false;  // from the run file (else the default)
};

struct OutputSpec {
  bool node_positions = false;   // write all node positions per step (large)
  long checkpoint_every = 1;     // steps between checkpoints; 0 = none
  bool keep_final_state = true;  // final_state.h5 in the results, for `mresim extend`/`rerun`
};

// ---------------------------------------------------------------------------------------------
// Derived geometry (computed while reading: it is what validates the placement)

// Springs that get the particle constants, by kind (a subset of the closed-form totals).
struct ParticleSpringCounts {
  std::int64_t edge = 0;
  std::int64_t face = 0;
  std::int64_t body = 0;
  std::int64_t total() const { return edge + face + body; }
};

struct MessGeometry {
  double element_length = 0.0;  // l_e, m
  lattice::GridShape shape;
  Eigen::Vector3d box_lengths = Eigen::Vector3d::Zero();  // (N_a - 1) l_e, m
  std::vector<std::array<int, 3>> centre_cells;           // cell holding each particle centre
  std::vector<Eigen::Vector3d> particle_centres;          // centres of those cells, m
  std::int64_t nodes_per_particle = 0;
  lattice::SpringCounts springs;          // all springs of the box (closed forms)
  ParticleSpringCounts particle_springs;  // of which with the particle constants
  double volume_fraction = 0.0;           // N V_p / (L_x L_y L_z) of the lattice (eq. 4.50)

  std::int64_t node_count() const { return shape.node_count(); }
  std::int64_t cell_count() const { return shape.cell_count(); }
  std::size_t particle_count() const { return centre_cells.size(); }
};

// At most this many nodes (a run needs ~1,000 bytes each: kBytesPerNode, check_memory); larger
// boxes are rejected before anything of that size is allocated.
inline constexpr std::int64_t kMaxNodes = 100'000'000;

// Sizes the box, places and voxelizes the particles (lattice::place_particles) and counts the
// springs, without building the lattice: fast even for the 1M-node helix. Throws
// std::invalid_argument as the lattice does (invalid parameters, a particle outside the box,
// overlapping particles, more than kMaxNodes nodes).
MessGeometry derive_geometry(const lattice::LatticeSpec& spec);

// ---------------------------------------------------------------------------------------------
// The whole run file

// Regular placements: the actual volume fraction of the lattice may differ from
// particles.volume_fraction by this much (relative) before the reader warns.
inline constexpr double kVolumeFractionTolerance = 0.01;

// particles.radius must lie in [kMinRadius, kMaxRadius] m: l_e, R^3 and R^6 (products of two
// dipole moments) stay normal doubles with room for the other factors.
inline constexpr double kMinRadius = 1e-30;
inline constexpr double kMaxRadius = 1e30;

struct MessSpec {
  std::string run_type;  // [run].type, the protocol's name
  std::string title;     // [run].title
  // The protocol with its own table's settings (protocols/protocol.hpp); shared by copies of the
  // spec (immutable).
  std::shared_ptr<const mess_protocol::Protocol> protocol;

  // [model] profile: the table entry, read once here and passed down (never compared by name).
  const mess::ModelProfile* profile = &mess::model_profile("physical");
  // [model], the particle radius and the placement: ready for lattice::build_lattice (the
  // profile's lattice rules already written in).
  lattice::LatticeSpec lattice;
  lattice::PlacementKind placement_kind = lattice::PlacementKind::regular;
  std::optional<double> requested_volume_fraction;  // regular placements
  std::optional<lattice::BoxSpec> box;              // [box], by_hand / chain / helix

  // [particles], magnetic part. particles.radius == lattice.particle_radius.
  magnetism::MagneticParticles particles;
  bool demagnetization = false;
  magnetism::SelfEnergyForm self_energy = magnetism::SelfEnergyForm::consistent;

  FieldSpec field;
  SolverSpec solver;
  AnalysisSpec analysis;
  OutputSpec output;

  MessGeometry geometry;

  // Read-time warnings (input that the model changes, e.g. the actual volume fraction of a
  // regular placement), one line each without "mresim: warning: "; the run type prints them and
  // records them in results.h5 /@warnings.
  std::vector<std::string> warnings;

  // The optional energy terms chosen by [terms.<name>] tables (mess::read_term_tables), for
  // the system (MessSystem's constructor).
  std::vector<mess::TermSpec> terms;

  // Load values of the protocol (strain or stress; 1 for protocols without a load).
  std::size_t load_step_count() const;
  // Relaxations the run performs: fields x load values.
  std::size_t relaxation_count() const;
  // Whether the run keeps, per field, the result at the load value before the slot's, for the
  // next load step's secant (solver.load_step_start = "extrapolated", more than one load value,
  // a protocol that loads from the zero-load state; ProtocolState::earlier_load_results).
  bool keeps_earlier_load_results() const;
  // Whether the run keeps the field result before the last, for the next field step's secant
  // (solver.field_step_start = "extrapolated" without load values;
  // ProtocolState::earlier_field_result).
  bool keeps_earlier_field_result() const;
};

// Reads every table of the 3D schema except [run] ([model], [particles], [box], [field],
// [strain] or [stress], [solver], [output]) for the run type `run_type` (one of
// mess_run_type_names(); anything else is a programming error: std::invalid_argument).
// Throws config::ConfigError for any invalid input, naming the key. Does not reject unknown
// keys: app::make_plan does that after the factory returns.
MessSpec read_mess_spec(const config::TableReader& root, std::string_view run_type);

// What app::make_plan will do once the run types are registered: reads [run] (type one of the
// four names, title, threads), then read_mess_spec, then rejects unknown keys anywhere.
MessSpec read_mess_run_file(const config::TableReader& root);

// ---------------------------------------------------------------------------------------------
// Memory (docs/run-files-3d.md, "Memory"): a run is refused before anything is allocated or
// written when its estimated peak exceeds the memory available to the process.

// Measured peak resident memory of a 3D run with the minimiser, per lattice node (nodes,
// springs, cells, forces, the minimiser's history, the seed's correction passes and the
// checkpoint copy together), the process's own memory included, rounded up: the full-size
// Fig. 4.11 pair (284,592 nodes) peaks at 987 bytes per node over its first three steps with the
// default multilevel preconditioner (solver.method = "minimiser" from
// mess::kMultilevelMinimumNodes nodes on) and below that with "lbfgs" (docs/performance.md).
inline constexpr std::int64_t kBytesPerNode = 1000;
// The same with solver.method = "newton": the elastic Hessian's sparse matrix (81 entries per
// row, 2.9 kB per node) and the multigrid built on it come on top; measured peak RSS 311 MiB at
// 48,600 nodes and 1,696 MiB at 284,592 nodes (the full-size Fig. 4.11 pair), a slope of
// 6,150 bytes per node, rounded up.
inline constexpr std::int64_t kNewtonBytesPerNode = 6400;
// The per-node figure for the spec's solver.
std::int64_t bytes_per_node(const MessSpec& spec);
// The process itself (libraries, HDF5, buffers): peak RSS of the 1,800-node run is 20 MB.
inline constexpr std::int64_t kFixedBytes = 32LL << 20;

// Strain and stress runs (more than one load value) keep two states per field for the run's
// whole length: the latest one, which the field's next load step starts from, and the
// zero-load reference its loads are measured from (two 3 x nodes arrays of doubles). They wait
// in an unnamed scratch file beside the results, not in memory (protocols/kept_positions.hpp):
// measured in memory, the full-size Fig. 4.25 helix (993,168 nodes) grew by these 48 bytes per
// node with every field.
inline constexpr std::int64_t kPerFieldScratchBytesPerNode = 48;
// Strain runs with solver.load_step_start = "extrapolated" keep a third array per field there
// (the result at the load value before, ProtocolState::earlier_load_results) and, for the
// run, the step's secant while it relaxes and the two previous fields' secant misses.
inline constexpr std::int64_t kEarlierLoadScratchBytesPerNode = 24;
inline constexpr std::int64_t kSecantScratchBytesPerNode = 72;
// The scratch file's size per node at most: kPerFieldScratchBytesPerNode x fields for runs with
// more than one load value (plus the arrays above where the run keeps them), else 0. On disk;
// not part of the memory estimate.
std::int64_t scratch_bytes_per_node(const MessSpec& spec);

// kFixedBytes + bytes_per_node x nodes + the magnetization solve's
// dense 3N x 3N matrices (Hessian, its factorization, the eigen-decomposition and Anderson's
// history: 4 x 8 (3N)^2 bytes for N particles).
std::int64_t estimated_memory_bytes(const MessSpec& spec);

struct AvailableMemory {
  std::optional<std::int64_t> bytes;  // std::nullopt: unknown (no check)
  std::string source;                 // "MRESIM_MEMORY_LIMIT", "MemAvailable", "cgroup memory.max"
};
// MRESIM_MEMORY_LIMIT (bytes, a positive integer) when set; otherwise the smaller of MemAvailable
// in /proc/meminfo and the cgroup limit /sys/fs/cgroup/memory.max. Throws config::ConfigError for
// an MRESIM_MEMORY_LIMIT that is not a positive integer.
AvailableMemory available_memory();

// Throws config::ConfigError (one line: nodes, the estimate, the memory available and where that
// figure comes from) when estimated_memory_bytes(spec) exceeds `available`.
void check_memory(const MessSpec& spec, const AvailableMemory& available);

// Adds to `report` everything the spec implies without running: lattice counts (nodes, cells,
// springs by kind), l_e, spring constants and kappa of the profile and the lattice moduli they
// give, the characteristic scales (m_c, k_eff, t_c), system size, particles and their centres,
// the actual volume fraction, the field and load sequences and the solver settings.
void describe_mess(const MessSpec& spec, app::InfoReport& report);

}  // namespace mresim::mess_config
