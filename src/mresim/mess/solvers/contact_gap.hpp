#pragma once

// Whether the minimisers' multilevel preconditioner solves the polymer between particles in
// contact exactly (contact_gap_blocks.hpp; the default), or leaves it to the node scaling and
// the coarse levels (the preconditioner before the gap blocks, kept to measure against). Run
// files: solver.contact_gap (docs/run-files-3d.md).

namespace mresim::mess {

enum class ContactGap { exact, none };

}  // namespace mresim::mess
