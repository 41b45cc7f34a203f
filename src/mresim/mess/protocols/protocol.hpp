#pragma once

// The protocol interface of the 3D model (Section 4.2.7) and its registry.
//
// A protocol is what a 3D run does with the lattice: which run-file table(s) it reads
// ([strain], [stress], none), which relaxation steps it plans (fields x load values), which
// boundary conditions and applied forces each step has (loading.hpp), what strain a step
// reached, and which analysis its results get (a modulus fit or none). Each protocol lives in
// its own .cpp file under src/mresim/mess/protocols/ and registers itself there, as the run
// types do (app/run_type.hpp):
//
//   namespace {
//   const ProtocolRegistrar magnetostriction_protocol_registrar({
//       "mess_magnetostriction", "3D lattice (MESS): ...", {},
//       [](const config::TableReader&) { return std::make_shared<const Magnetostriction>(); }});
//   }
//
// Registering a protocol also registers the run type of the same name ([run] type), so a new
// protocol is one file, its test, its section in docs/run-files-3d.md and an example
// (src/mresim/mess/README.md, "How to add a protocol"). The library is linked whole
// (WHOLE_ARCHIVE), so the registrars run although nothing references them.
//
// The runner (protocol_runner.cpp), the step plan (step_plan.cpp), `mresim info`
// (describe_mess.cpp) and the outputs (mess_outputs.cpp) only call this interface; nothing
// outside the protocol files asks which protocol a run has.

#include <Eigen/Core>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "mresim/app/info_report.hpp"
#include "mresim/config/table_reader.hpp"
#include "mresim/mess/lattice/lattice.hpp"
#include "mresim/mess/protocols/loading.hpp"
#include "mresim/mess/protocols/step_plan.hpp"
#include "mresim/mess/run_file/mess_spec.hpp"

namespace mresim::mess_protocol {

// The analysis of a protocol's results (Section 4.2.8), written to /analysis and modulus.csv.
enum class AnalysisKind {
  none,            // hysteresis, magnetostriction: the per-step outputs only
  energy_modulus,  // strain runs: energy density = modulus x^2/2 + c per field (eq. 4.97)
  stress_modulus,  // stress runs: stress = modulus x through 0 per field
};

struct Analysis {
  AnalysisKind kind = AnalysisKind::none;
  std::string modulus_name;  // "G_eff", "E_eff", "torsion_stiffness"
  // energy_modulus: the original's zero-point rule (modulus_fit.hpp), used for shear.
  bool drop_zero_point_above_next = false;
};

class Protocol {
 public:
  virtual ~Protocol() = default;

  // The load values, first 0 (strain in rad or 1, stress in Pa, as the step's load_value);
  // {0} for protocols without a load.
  [[nodiscard]] virtual std::vector<double> load_values() const { return {0.0}; }
  // Whether the protocol has a load axis (a [strain] or [stress] table), even with one value.
  [[nodiscard]] virtual bool has_load() const { return false; }
  // The unit of the load values ("rad", "1", "Pa"); "1" without a load.
  [[nodiscard]] virtual const char* load_unit() const { return "1"; }

  // The relaxation steps: by default an outer loop over load_values() and an inner loop over
  // the fields, step n = load_index x F + field_index (docs/original-code.md#step-order).
  [[nodiscard]] virtual std::vector<StepSpec> plan_steps(const mess_config::MessSpec& spec) const;

  // Whether a loaded step (load_index > 0) is measured from the zero-load result at its field
  // (strain runs) instead of the initial lattice.
  [[nodiscard]] virtual bool loads_from_zero_load_state() const { return false; }
  // The boundary conditions and applied forces of `step`; `reference` is the initial lattice,
  // or the zero-load result at this field where loads_from_zero_load_state() says so.
  [[nodiscard]] virtual LoadState load(const lattice::Lattice& lattice, const StepSpec& step,
                                       const Eigen::Matrix3Xd& reference) const = 0;
  // The strain a relaxed step reached (StepRecord::measured_strain): `zero_load` is the
  // zero-load result at this field (the step's own positions at load_index 0). 0 by default.
  [[nodiscard]] virtual double measured_strain(const lattice::Lattice& lattice,
                                               const StepSpec& step,
                                               const Eigen::Matrix3Xd& positions,
                                               const Eigen::Matrix3Xd& zero_load) const;

  [[nodiscard]] virtual Analysis analysis() const { return {}; }

  // Read-time check of the load's scales (top: the largest force scale whose squares summed over
  // the nodes stay finite, N; elastic: k_eff l_e, N); throws config::ConfigError on its table.
  virtual void check_scales(const config::TableReader& root, const mess_config::MessSpec& spec,
                            double top, double elastic) const;
  // `mresim info`: the protocol's own section ([strain], [stress]); nothing by default.
  virtual void describe(const mess_config::MessSpec& spec, app::InfoReport& report) const;
};

// A protocol with settings read from its table; settings_of() gives tests and tools typed
// access without naming the protocol's class.
template <typename Settings>
class ProtocolWith : public Protocol {
 public:
  explicit ProtocolWith(Settings settings) : settings_(std::move(settings)) {}
  [[nodiscard]] const Settings& settings() const { return settings_; }

 private:
  Settings settings_;
};

// The settings of the spec's protocol when it holds a `Settings` (e.g. mess_config::StrainSpec),
// else nullptr.
template <typename Settings>
const Settings* settings_of(const mess_config::MessSpec& spec) {
  const auto* p = dynamic_cast<const ProtocolWith<Settings>*>(spec.protocol.get());
  return p != nullptr ? &p->settings() : nullptr;
}

// Reads the protocol's own tables from the whole run file; throws config::ConfigError for bad
// input, naming the key.
using ProtocolReader =
    std::function<std::shared_ptr<const Protocol>(const config::TableReader& root)>;

struct ProtocolType {
  std::string name;                 // [run] type, e.g. "mess_strain"
  std::string summary;              // one line for `mresim types`
  std::vector<std::string> tables;  // run-file tables only this protocol reads, e.g. {"strain"}
  ProtocolReader read;
  // [field] sequence when the file gives none (read before the protocol's own table).
  mess_config::FieldSequence default_field_sequence = mess_config::FieldSequence::up;
  // Position in the lists of 3D run types (messages naming the allowed ones), then by name:
  // hysteresis 1, strain 2, magnetostriction 3, stress 4, as the messages always read.
  int order = 100;
};

// Adds a protocol and the run type of the same name. Registering a name twice aborts at
// start-up (a build mistake).
void register_protocol(ProtocolType type);

struct ProtocolRegistrar {
  explicit ProtocolRegistrar(ProtocolType type) { register_protocol(std::move(type)); }
};

// Every registered protocol, sorted by (order, name).
const std::vector<ProtocolType>& protocol_types();
// Their names, in that order.
std::vector<std::string> protocol_names();
// The protocol of that name; std::invalid_argument naming the registered ones otherwise.
const ProtocolType& find_protocol(std::string_view name);

// Reads the protocol tables of the run file for [run] type `name`: this protocol's tables, and
// refuses a table another protocol reads ("only read by [run] type = ..."), in the order of the
// registry, so that the first problem a user meets is reported as it always was.
std::shared_ptr<const Protocol> read_protocol(const config::TableReader& root,
                                              std::string_view name);

}  // namespace mresim::mess_protocol
