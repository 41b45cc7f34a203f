#pragma once

// The lattice's grid split over MPI processes by PETSc's DMDA (a structured grid with 3 degrees
// of freedom per node and a box stencil of width 1): each process owns a box of nodes and sees
// one layer of ghost nodes around it, which is all a spring (to one of the 26 neighbours) or a
// cell (to its 7 other corners) needs. The groundwork of distributed 3D relaxation
// (docs/mpi.md): distributed_elastic.hpp evaluates the elastic terms on it.
//
// Node order. The lattice numbers node (ix, iy, iz) as iz + nz (ix + nx iy)
// (lattice/grid.hpp); a DMDA numbers (i, j, k) in its natural order as i + M (j + N k). So the
// DMDA's axes are (i, j, k) = (iz, ix, iy), with (M, N, P) = (nz, nx, ny): its natural order is
// the lattice's node order. PETSc's global vectors are ordered by process instead; gather() and
// scatter() convert between them and whole 3 x N matrices in node order.
//
// PETSc (and MPI) are initialised on first use (initialise_petsc(): a single process needs no
// mpirun). Errors become std::runtime_error with PETSc's message.

// (PETSc's headers include MPI's without its C++ bindings, which nothing links.)
#include <petscdm.h>
#include <petscvec.h>

#include <Eigen/Core>
#include <array>
#include <cstdint>

#include "mresim/mess/lattice/grid.hpp"
#include "mresim/mess/solvers/amg_preconditioner.hpp"  // initialise_petsc, check_petsc

namespace mresim::mess {

// Lower corner and extent of a box of nodes in lattice coordinates (ix, iy, iz).
struct NodeBox {
  std::array<int, 3> lower{};
  std::array<int, 3> size{};

  [[nodiscard]] std::int64_t node_count() const {
    return std::int64_t{size[0]} * size[1] * size[2];
  }
  [[nodiscard]] bool contains(int ix, int iy, int iz) const {
    return ix >= lower[0] && ix < lower[0] + size[0] && iy >= lower[1] && iy < lower[1] + size[1] &&
           iz >= lower[2] && iz < lower[2] + size[2];
  }
  // Index of node (ix, iy, iz) in an array over this box in the lattice's order (iz fastest,
  // then ix, then iy); the node must be in the box.
  [[nodiscard]] std::int64_t offset(int ix, int iy, int iz) const {
    return (iz - lower[2]) +
           std::int64_t{size[2]} * ((ix - lower[0]) + std::int64_t{size[0]} * (iy - lower[1]));
  }
};

class LatticeDecomposition {
 public:
  // `processes` = how many processes along (x, y, z); 0 lets PETSc choose (PETSC_DECIDE).
  // Collective on `comm`. Throws std::invalid_argument for an invalid grid, or a split that
  // is not possible (can_split).
  LatticeDecomposition(const lattice::GridShape& shape, MPI_Comm comm,
                       std::array<int, 3> processes = {0, 0, 0});
  LatticeDecomposition(const LatticeDecomposition&) = delete;
  LatticeDecomposition& operator=(const LatticeDecomposition&) = delete;
  LatticeDecomposition(LatticeDecomposition&&) = delete;
  LatticeDecomposition& operator=(LatticeDecomposition&&) = delete;
  ~LatticeDecomposition();

  // Whether `size` processes can share the grid with `processes` per axis (0: any): each
  // process needs at least one node along every axis.
  [[nodiscard]] static bool can_split(const lattice::GridShape& shape, int size,
                                      std::array<int, 3> processes = {0, 0, 0});

  [[nodiscard]] const lattice::GridShape& shape() const { return shape_; }
  [[nodiscard]] MPI_Comm comm() const { return comm_; }
  [[nodiscard]] DM dm() const { return dm_; }
  // This process's nodes, and those plus the ghost layer (clipped at the box's faces).
  [[nodiscard]] const NodeBox& owned() const { return owned_; }
  [[nodiscard]] const NodeBox& ghosted() const { return ghosted_; }

  // A new global vector (3 values per owned node, in the owned box's order); the caller
  // destroys it (VecDestroy).
  [[nodiscard]] Vec create_global_vector() const;
  // Collective: every process passes the same 3 x N matrix in node order; each copies its own
  // nodes into `global`.
  void scatter(const Eigen::Matrix3Xd& all, Vec global) const;
  // Collective: the whole 3 x N matrix in node order, on every process.
  [[nodiscard]] Eigen::Matrix3Xd gather(Vec global) const;

 private:
  lattice::GridShape shape_;
  MPI_Comm comm_;
  DM dm_ = nullptr;
  NodeBox owned_;
  NodeBox ghosted_;
  // gather()'s natural-order vector, its copy on every process and the scatter between them.
  mutable Vec natural_ = nullptr;
  mutable Vec whole_ = nullptr;
  mutable VecScatter to_all_ = nullptr;
};

// Collective: total[i] = the sum over the processes of local[i], added in rank order, so that
// every process gets bitwise the same totals whatever algorithm MPI_Allreduce would use.
void sum_in_rank_order(MPI_Comm comm, const double* local, double* total, int count);

}  // namespace mresim::mess
