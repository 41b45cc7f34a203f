#pragma once

// What a 3D run leaves in its output directory (docs/outputs-3d.md):
//   results.h5     /lattice (grid, box, particles; cells and initial nodes with node
//                  positions), /steps (one entry per step: field, load, energies by term,
//                  energy density, centres, magnetizations, separations, clusters, solver
//                  diagnostics), /analysis (strain and stress runs: modulus per field, MR effect)
//   summary.csv    one row per step
//   modulus.csv    strain and stress runs: one row per field
//                  and the H5MD view of the trajectory (/h5md, /particles, /observables,
//                  /parameters; h5md_outputs.hpp)
//   positions/step_NNNNNN.h5   with [output] node_positions = true: the deformed lattice per
//                  step (positions and displacements, compressed)
//   mess.xdmf, particles.xdmf, xdmf/   the ParaView views (xdmf_outputs.hpp)

#include <filesystem>
#include <string>
#include <vector>

#include "mresim/app/invalid_results.hpp"
#include "mresim/io/hdf5_file.hpp"
#include "mresim/mess/protocols/protocol_runner.hpp"

namespace mresim::mess_protocol {

// positions/step_NNNNNN.h5: datasets /positions and /displacement (positions - `initial`),
// N x 3, m, chunked and compressed (shuffle + gzip); written atomically.
std::filesystem::path step_positions_file(const std::filesystem::path& run_dir, std::size_t step);
void write_step_positions(const std::filesystem::path& run_dir, std::size_t step,
                          const Eigen::Matrix3Xd& positions, const Eigen::Matrix3Xd& initial);

// What is wrong with the results of a run (docs/outputs-3d.md, "Invalid results"):
//  - non-finite numbers of a step (written as NaN, the step's /steps/valid = 0),
//  - steps that did not converge (/steps/solver/converged = 0 and /steps/valid = 0),
//  - moduli whose fit is not a result (/analysis/valid = 0, the reason in /analysis/problem).
// The first two make the run's results invalid (message(), then app::InvalidResults); invalid
// fits are warnings (the steps they come from are fine, the analysis cannot use them).
struct MessResultCheck {
  app::ResultCheck non_finite{"non-finite results"};
  app::ResultCheck unconverged{"unconverged steps"};
  std::vector<std::string> invalid_fits;  // "G_eff at |B| = 0.14 T (field 3): <problem>"

  // "" when no step is invalid; otherwise the one-line InvalidResults message.
  [[nodiscard]] std::string message() const;
};

// Per step: 1 when every number of the step is finite and it converged. Records the problems
// in `check`, naming the step, its field along the field direction and its load.
std::vector<std::int64_t> check_steps(const mess_config::MessSpec& spec,
                                      const std::vector<StepRecord>& records,
                                      MessResultCheck& check);

// The records with every non-finite number (energies, volume, strain, centres,
// magnetizations, solver diagnostics) replaced by NaN, as they are written.
std::vector<StepRecord> with_nan_for_non_finite(std::vector<StepRecord> records);

// Everything above except the per-step position files (written as the steps finish). Returns
// what is invalid; the caller warns and throws (runs/mess_runs.cpp).
MessResultCheck write_mess_results(const std::filesystem::path& run_dir, io::Hdf5File& results,
                                   const ProtocolRunner& runner,
                                   const std::vector<StepRecord>& computed);

}  // namespace mresim::mess_protocol
