#pragma once

// The H5MD view of a 3D run's trajectory in results.h5 (H5MD 1.1,
// https://www.nongnu.org/h5md/h5md.html; docs/outputs-3d.md, "H5MD"), written beside /lattice
// and /steps, which stay as they are:
//   /h5md                               version [1, 1], author, creator (mresim, its version)
//   /particles/magnetic_particles       position (nm), magnetization (A/m) per step; box
//   /particles/nodes                    with node positions: every node's position per step, a
//                                       virtual dataset over positions/step_NNNNNN.h5 (m)
//   /observables/<name>                 per-step scalars and vectors: field, load, energies, ...
//   /parameters                         the lattice and particle constants
// `step` is the step index, `time` the step index too (quasi-static steps have no time; the
// applied field and load are observables). Most values are hard links to the /steps datasets,
// so the two views cannot disagree and cost no space.

#include <vector>

#include "mresim/io/hdf5_file.hpp"
#include "mresim/mess/protocols/protocol_runner.hpp"

namespace mresim::mess_protocol {

// After /lattice and /steps are written (write_mess_results); the node trajectory refers to
// positions/step_NNNNNN.h5 beside results.h5.
void write_h5md(io::Hdf5File& results, const ProtocolRunner& runner,
                const std::vector<StepRecord>& records);

}  // namespace mresim::mess_protocol
