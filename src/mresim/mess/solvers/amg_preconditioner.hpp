#pragma once

// Algebraic multigrid for the lattice's elastic Hessian: one V-cycle of PETSc's GAMG (smoothed
// aggregation) per application, set up once on an ElasticMatrix (hessian_assembly.hpp) and
// applied as the preconditioner of the Newton solver's conjugate gradients (newton.hpp).
//
// Why GAMG. Measured on the Phi = 3 % pair's elastic Hessian (particles 1e4 times stiffer than
// the polymer): CG to 1e-8 needs 30-47 iterations from 1.4k to 48k nodes with GAMG, 55-67 with
// hypre's BoomerAMG and 174-1,369 with Jacobi (docs/performance.md). The iteration count of a
// multilevel preconditioner barely grows with the lattice, which is what makes a relaxation's
// cost grow like N. Settings: 3 dof per node (block size 3), the six rigid-body modes of the
// node positions as the near-null space (translations and rotations cost no elastic energy),
// one smoothing step of the prolongator, a strength threshold of 0.02, Chebyshev/Jacobi
// smoothing (GAMG's defaults).
//
// PETSc is initialised on first use (MPI as a singleton: no mpirun needed) and finalised at
// exit. Errors become std::runtime_error with PETSc's message.

#include <Eigen/Core>
#include <memory>

#include "mresim/mess/solvers/hessian_assembly.hpp"

namespace mresim::mess {

// Initialises PETSc and MPI now (idempotent; the preconditioner calls it too). A program that
// will use the multigrid calls it before it opens files that another process must open while
// it runs: MPI's singleton start (no mpirun) forks a helper process, which inherits the open
// file descriptors and with them HDF5's file locks (the plot script then could not read
// results.h5).
void initialise_petsc();

// Throws std::runtime_error("PETSc <what>: <PETSc's message>") unless code is 0 (the PETSc
// error handler set by initialise_petsc() returns errors instead of printing them).
void check_petsc(int code, const char* what);

struct AmgOptions {
  double threshold = 0.02;  // GAMG's strength-of-connection threshold
  int smoothings = 1;       // prolongator smoothing steps (smoothed aggregation)
};

class AmgPreconditioner {
 public:
  // `matrix` must stay alive and unchanged while this object exists (PETSc uses its arrays);
  // `coordinates` (3 x N, any length unit) give the rigid-body modes.
  AmgPreconditioner(const ElasticMatrix& matrix, const Eigen::Matrix3Xd& coordinates,
                    const AmgOptions& options = {});
  AmgPreconditioner(const AmgPreconditioner&) = delete;
  AmgPreconditioner& operator=(const AmgPreconditioner&) = delete;
  AmgPreconditioner(AmgPreconditioner&& other) noexcept;
  AmgPreconditioner& operator=(AmgPreconditioner&& other) noexcept;
  ~AmgPreconditioner();

  // out = one V-cycle applied to in (both 3N).
  void apply(const Eigen::VectorXd& in, Eigen::VectorXd& out) const;

  // Levels of the hierarchy GAMG built.
  int levels() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace mresim::mess
