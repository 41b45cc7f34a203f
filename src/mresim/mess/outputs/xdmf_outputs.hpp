#pragma once

// The XDMF 3 files through which ParaView reads a 3D run (docs/outputs-3d.md, "XDMF"):
//   mess.xdmf          with node positions: the deformed lattice of every step (hexahedra;
//                      node attributes particle_id and displacement, cell attribute
//                      material_id), Time = the step index
//   particles.xdmf     with particles: the particle centres of every step as a polyvertex grid
//                      with the magnetization vector and cluster_id (ParaView's Glyph filter
//                      draws the arrows), Time = the step index
//   xdmf/lattice_leg_NN.xdmf, xdmf/particles_leg_NN.xdmf
//                      the same per leg, with Time = the applied field along the field
//                      direction (T; field runs) or the load value (strain and stress runs)
// Every grid also carries its step's step index, field and load as grid attributes.
//
// A leg is a stretch of steps along which that time value strictly increases or decreases
// (a hysteresis loop 0 -> max -> -max -> max has three; a strain run one per field): XDMF
// takes grids of equal time for pieces of one grid, so a loop's repeated fields cannot share a
// file.

#include <filesystem>
#include <vector>

#include "mresim/mess/protocols/protocol_runner.hpp"

namespace mresim::mess_protocol {

// The legs of a run: each a list of positions in `records`, in step order. Field runs
// (has_load false): stretches of strictly monotone `field_projection`; load runs: the steps of
// each field, split into stretches of strictly monotone load value.
std::vector<std::vector<std::size_t>> xdmf_legs(const std::vector<StepRecord>& records,
                                                const std::vector<double>& field_projection,
                                                bool has_load);

// Writes the files above into `run_dir` (after results.h5's /lattice and /steps are written).
void write_xdmf_views(const std::filesystem::path& run_dir, const ProtocolRunner& runner,
                      const std::vector<StepRecord>& records,
                      const std::vector<double>& field_projection);

}  // namespace mresim::mess_protocol
