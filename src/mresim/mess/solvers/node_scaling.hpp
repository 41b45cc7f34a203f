#pragma once

// How the minimisers' multilevel preconditioner scales the polymer's nodes
// (preconditioner.hpp, "Node blocks"): by the inverse of each node's 3 x 3 block of the
// stiffness terms (the default), or by the inverse of its diagonal (the preconditioner before
// the blocks, kept to measure against). Run files: solver.node_scaling (docs/run-files-3d.md).

namespace mresim::mess {

enum class NodeScaling { blocks, diagonal };

}  // namespace mresim::mess
