#pragma once

// The energy-term interface of the 3D model (Section 4.2.4), in the spirit of MFEM's
// integrators and HOOMD-blue's evaluators: the system (system/system_energy.hpp) is a list of
// EnergyTerm objects, and everything that lists energies (results.h5 /steps/energies, the CSV
// columns, checkpoints, the plots) iterates that list. src/mresim/mess/README.md, "How to add
// an energy term", walks through one.
//
// Variables. A term sees the node positions x (3 x N, m), the particle centres c (3 x N_p, m,
// under the system's centre rule) and the magnetizations M (3 x N_p, A/m). Its gradient is
// taken with respect to x and c at fixed M (J/m): for the magnetic terms this is the total
// derivative at the self-consistent M by the envelope theorem (terms/magnetic_energy.hpp), and
// the system spreads dE/dc_p over the particle's n_p nodes (system_energy.hpp). Its Hessian
// is taken with respect to (x, c) at fixed M too: the change of M with the positions is not
// part of it.
//
// Potential. The forces are minus the gradient of sum_t force_factor_t E_t over the terms in
// the total. force_factor is 1 except for the volume term of the seed profile (4: the original
// code's volume forces, terms/elastic_terms.hpp). Each term's gradient, Hessian product and
// Hessian entries already include its force factor; its energy never does.
//
// Registration. Each term is one .cpp file that registers itself at program start:
//
//   namespace {
//   const mresim::mess::EnergyTermRegistrar wca_term_registrar({
//       .name = "wca", .order = 70, .always_present = true,
//       .make = [](const mresim::mess::TermContext&, const std::any&) {
//         return std::make_unique<WcaTerm>(); }});
//   }
//
// An optional term also gives `read`, which reads its own run-file table [terms.<name>] and
// returns its parameters (any copyable type, e.g. a struct); the term is then present exactly
// when the run file has that table, and `make` receives what `read` returned. The library is
// linked whole (CMakeLists.txt, WHOLE_ARCHIVE), so the registrar is never dropped.

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <any>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "mresim/config/table_reader.hpp"
#include "mresim/mess/lattice/lattice.hpp"
#include "mresim/mess/magnetization/dipole_field.hpp"
#include "mresim/mess/system/mess_settings.hpp"
#include "mresim/mess/terms/hessian_blocks.hpp"
#include "mresim/mess/terms/magnetic_energy.hpp"

namespace mresim::mess {

// What a term is evaluated at. All references stay valid for the duration of one call.
struct TermState {
  const lattice::Lattice& lattice;
  const Eigen::Matrix3Xd& positions;       // x, 3 x N, m
  const Eigen::Matrix3Xd& centres;         // c, 3 x N_p, m (the system's centre rule)
  const Eigen::Matrix3Xd& magnetizations;  // M, 3 x N_p, A/m
  const magnetism::MagneticModel& model;   // particles, H_ext, self-energy form, WCA
  const Eigen::Matrix3Xd& applied_forces;  // N, 3 x N, or 3 x 0 when there are none
  const MessSettings& settings;
  // The pairs of the free block at `centres` (OpenBoundary{}.pairs(centres)), computed once per
  // evaluation for all pair terms; empty with fewer than two particles.
  const magnetism::PairList& pairs;
};

// A gradient, Hessian-vector product or direction: one part per variable (J/m for gradients).
struct TermGradient {
  Eigen::Matrix3Xd nodes;    // d/dx, 3 x N
  Eigen::Matrix3Xd centres;  // d/dc, 3 x N_p

  // Zeros of the shapes of `state`.
  static TermGradient zero(const TermState& state);
};

struct TermValue {
  double energy = 0.0;  // J (without the force factor)
  // The energy's rounding error is about machine epsilon times this, beyond eps |energy|
  // (e.g. sum k |l - L| l for the springs, whose stretches are differences of nearly equal
  // numbers); 0 when there is no such cancellation. Line searches use it.
  double rounding = 0.0;
};

// How a term provides its Hessian.
enum class HessianKind {
  exact,              // an exact formula
  zero,               // the Hessian vanishes (e.g. Zeeman in a uniform field, load)
  central_difference  // the default: central differences of the gradient (see below)
};

class EnergyTerm {
 public:
  virtual ~EnergyTerm() = default;

  // The dataset name under /steps/energies and the CSV column E_<name>_J: lower case, unique.
  [[nodiscard]] virtual std::string_view name() const = 0;
  // The dissertation's equation, e.g. "eq. 4.62" (written as the dataset's `equation`).
  [[nodiscard]] virtual std::string_view equation() const = 0;
  // The plot label, e.g. "springs" (written as the dataset's `title`).
  [[nodiscard]] virtual std::string_view title() const = 0;
  // False for terms that are reported only (eq. 4.73's self-energy): not in the total, not in
  // the potential, no gradient.
  [[nodiscard]] virtual bool in_total() const { return true; }
  // The weight of this term in the potential (see the header comment).
  [[nodiscard]] virtual double force_factor(const TermState& /*state*/) const { return 1.0; }

  // The energy at `state`. If `gradient` is not null, force_factor times the gradient is ADDED
  // to it (gradient->nodes 3 x N, gradient->centres 3 x N_p, both of the state's shapes).
  // Must be bitwise independent of the OpenMP thread count (system/fixed_order.hpp).
  [[nodiscard]] virtual TermValue evaluate(const TermState& state,
                                           TermGradient* gradient) const = 0;

  [[nodiscard]] virtual HessianKind hessian_kind() const { return HessianKind::central_difference; }
  // ADDS force_factor times H v to `out`, H the Hessian with respect to (x, c) at fixed M.
  // The default: (g(s + h v) - g(s - h v)) / (2 h) with g the gradient of evaluate() and
  // h = 1e-5 l_e / max|v| (relative error about 1e-10 for terms that vary on the scale of
  // the particle radius); terms with a cheap exact formula override it.
  virtual void add_hessian_product(const TermState& state, const TermGradient& v,
                                   TermGradient& out) const;
  // Whether add_hessian_blocks is available: the elastic terms (springs, volume), whose
  // Hessian is a sparse matrix over the node coordinates only.
  [[nodiscard]] virtual bool has_hessian_entries() const { return false; }
  // ADDS force_factor times the Hessian with respect to the node coordinates to `sink`, as
  // 3 x 3 node blocks (terms/hessian_blocks.hpp). The default throws std::logic_error.
  virtual void add_hessian_blocks(const TermState& state, HessianBlockSink& sink) const;
  // The same as triplets (row/column 3 n + a for coordinate a of node n; duplicates are
  // summed by setFromTriplets).
  void add_hessian_entries(const TermState& state,
                           std::vector<Eigen::Triplet<double>>& entries) const {
    TripletSink sink(entries);
    add_hessian_blocks(state, sink);
  }
};

// ------------------------------------------------------------------------------ registry

// What a factory may use besides its own parameters. Valid only during the factory call (the
// system is moved and copied): a term copies what it keeps and reads the rest from TermState.
struct TermContext {
  const lattice::Lattice& lattice;
  const magnetism::MagneticModel& model;
  const MessSettings& settings;
};

// An optional term chosen by the run file: its name and what its reader returned.
struct TermSpec {
  std::string name;
  std::any parameters;
};

using TermReader = std::function<std::any(const config::TableReader& table)>;
using TermFactory =
    std::function<std::unique_ptr<EnergyTerm>(const TermContext& context, const std::any& p)>;

struct TermRegistration {
  std::string name;             // as EnergyTerm::name(); the run-file table [terms.<name>]
  double order = 0.0;           // position in the list (ascending); the built-in terms use
                                // springs 10, volume 20, zeeman 30, dipole 40, self 50,
                                // self_linearized 60, wca 70, load 80
  bool always_present = false;  // true: in every system, no run-file table
  TermReader read;              // optional terms: reads [terms.<name>] (ConfigError if bad)
  TermFactory make;             // builds the term for one system
};

// Adds a term; registering the same name twice aborts the program at start-up.
void register_energy_term(TermRegistration registration);

struct EnergyTermRegistrar {
  explicit EnergyTermRegistrar(TermRegistration registration) {
    register_energy_term(std::move(registration));
  }
};

// All registered terms in list order (ascending order, then name).
const std::vector<TermRegistration>& energy_term_registrations();
// nullptr if no term has this name.
const TermRegistration* find_energy_term(std::string_view name);

// The run file's hook (run_file/read_mess_spec.cpp calls it once): for every optional term in
// registry order whose table [terms.<name>] is present, its reader's result. Tables of unknown
// or always-present terms are left unread, so the run file's unknown-key check names them.
std::vector<TermSpec> read_term_tables(const config::TableReader& root);

// The terms of one system: every always-present term and the given optional ones, in list
// order. Throws std::invalid_argument for an unknown or always-present name in `optional`.
std::vector<std::unique_ptr<EnergyTerm>> make_energy_terms(const TermContext& context,
                                                           const std::vector<TermSpec>& optional);

}  // namespace mresim::mess
