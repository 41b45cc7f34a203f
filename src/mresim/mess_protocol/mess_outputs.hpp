#pragma once

// What a 3D run leaves in its output directory (docs/outputs-3d.md):
//   results.h5     /lattice (grid, box, particles; cells and initial nodes with node
//                  positions), /steps (one entry per step: field, load, energies by term,
//                  energy density, centres, magnetizations, separations, clusters, solver
//                  diagnostics), /analysis (strain and stress runs: modulus per field, MR effect)
//   summary.csv    one row per step
//   modulus.csv    strain and stress runs: one row per field
//   positions/step_NNNNNN.h5 and mess.xdmf   with [output] node_positions = true: the deformed
//                  lattice per step, for ParaView (Hexahedron cells, node attribute particle_id)

#include <filesystem>
#include <vector>

#include "mresim/io/hdf5_file.hpp"
#include "mresim/mess_protocol/protocol_runner.hpp"

namespace mresim::mess_protocol {

// positions/step_NNNNNN.h5 (dataset /positions, N x 3, m), written atomically.
std::filesystem::path step_positions_file(const std::filesystem::path& run_dir, std::size_t step);
void write_step_positions(const std::filesystem::path& run_dir, std::size_t step,
                          const Eigen::Matrix3Xd& positions);

// Everything above except the per-step position files (written as the steps finish).
void write_mess_results(const std::filesystem::path& run_dir, io::Hdf5File& results,
                        const ProtocolRunner& runner, const std::vector<StepRecord>& records);

}  // namespace mresim::mess_protocol
