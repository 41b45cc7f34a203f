#include "mresim/mess/solvers/amg_preconditioner.hpp"

#include <petscksp.h>

#include <cstdlib>
#include <stdexcept>
#include <string>

namespace mresim::mess {

void check_petsc(int code, const char* what) {
  if (code == 0) return;
  const char* text = nullptr;
  (void)PetscErrorMessage(static_cast<PetscErrorCode>(code), &text, nullptr);
  throw std::runtime_error(std::string("PETSc ") + what + ": " +
                           (text != nullptr ? text : "error " + std::to_string(code)));
}

// PETSc (and MPI, as a singleton when the program was not started by mpirun) is finalised at
// exit. PETSc's errors are returned, not printed, so that check_petsc() can report them.
void initialise_petsc() {
  static const bool initialised = [] {
    PetscBool already = PETSC_FALSE;
    check_petsc(PetscInitialized(&already), "PetscInitialized");
    if (already == PETSC_FALSE) {
      check_petsc(PetscInitializeNoArguments(), "PetscInitialize");
      (void)std::atexit([] { (void)PetscFinalize(); });
    }
    check_petsc(PetscPushErrorHandler(PetscReturnErrorHandler, nullptr), "PetscPushErrorHandler");
    return true;
  }();
  (void)initialised;
}

struct AmgPreconditioner::Impl {
  Mat matrix = nullptr;
  PC pc = nullptr;
  Vec in = nullptr;
  Vec out = nullptr;
  PetscInt size = 0;

  Impl() = default;
  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;
  Impl(Impl&&) = delete;
  Impl& operator=(Impl&&) = delete;
  ~Impl() {
    (void)PCDestroy(&pc);
    (void)VecDestroy(&in);
    (void)VecDestroy(&out);
    (void)MatDestroy(&matrix);
  }
};

AmgPreconditioner::AmgPreconditioner(const ElasticMatrix& matrix,
                                     const Eigen::Matrix3Xd& coordinates, const AmgOptions& options)
    : impl_(std::make_unique<Impl>()) {
  static_assert(sizeof(PetscInt) == sizeof(std::int32_t), "PETSc with 32-bit indices expected");
  initialise_petsc();
  Impl& p = *impl_;
  p.size = matrix.rows();
  if (coordinates.size() != p.size) {
    throw std::invalid_argument("AmgPreconditioner: coordinates do not match the matrix");
  }
  // PETSc reads the arrays in place (no copy); it never writes them.
  // NOLINTBEGIN(cppcoreguidelines-pro-type-const-cast)
  check_petsc(MatCreateSeqAIJWithArrays(
                  PETSC_COMM_SELF, p.size, p.size, const_cast<PetscInt*>(matrix.row_start().data()),
                  const_cast<PetscInt*>(matrix.columns().data()),
                  const_cast<PetscScalar*>(matrix.values().data()), &p.matrix),
              "MatCreateSeqAIJWithArrays");
  // NOLINTEND(cppcoreguidelines-pro-type-const-cast)
  check_petsc(MatSetBlockSize(p.matrix, 3), "MatSetBlockSize");
  check_petsc(VecCreateSeqWithArray(PETSC_COMM_SELF, 3, p.size, nullptr, &p.in), "VecCreate");
  check_petsc(VecCreateSeqWithArray(PETSC_COMM_SELF, 3, p.size, nullptr, &p.out), "VecCreate");

  // The six rigid-body modes of the node positions as GAMG's near-null space.
  Vec xyz = nullptr;
  check_petsc(VecCreateSeqWithArray(PETSC_COMM_SELF, 3, p.size, coordinates.data(), &xyz),
              "VecCreate");
  MatNullSpace modes = nullptr;
  check_petsc(MatNullSpaceCreateRigidBody(xyz, &modes), "MatNullSpaceCreateRigidBody");
  check_petsc(MatSetNearNullSpace(p.matrix, modes), "MatSetNearNullSpace");
  (void)MatNullSpaceDestroy(&modes);
  (void)VecDestroy(&xyz);

  check_petsc(PCCreate(PETSC_COMM_SELF, &p.pc), "PCCreate");
  check_petsc(PCSetOperators(p.pc, p.matrix, p.matrix), "PCSetOperators");
  check_petsc(PCSetType(p.pc, PCGAMG), "PCSetType");
  check_petsc(PCGAMGSetType(p.pc, PCGAMGAGG), "PCGAMGSetType");
  check_petsc(PCGAMGSetNSmooths(p.pc, options.smoothings), "PCGAMGSetNSmooths");
  PetscReal threshold = options.threshold;
  check_petsc(PCGAMGSetThreshold(p.pc, &threshold, 1), "PCGAMGSetThreshold");
  check_petsc(PCSetFromOptions(p.pc), "PCSetFromOptions");  // PETSC_OPTIONS may refine it
  check_petsc(PCSetUp(p.pc), "PCSetUp (GAMG)");
}

AmgPreconditioner::AmgPreconditioner(AmgPreconditioner&&) noexcept = default;
AmgPreconditioner& AmgPreconditioner::operator=(AmgPreconditioner&&) noexcept = default;
AmgPreconditioner::~AmgPreconditioner() = default;

void AmgPreconditioner::apply(const Eigen::VectorXd& in, Eigen::VectorXd& out) const {
  Impl& p = *impl_;
  if (in.size() != p.size) throw std::invalid_argument("AmgPreconditioner::apply: wrong size");
  out.resize(p.size);
  check_petsc(VecPlaceArray(p.in, in.data()), "VecPlaceArray");
  check_petsc(VecPlaceArray(p.out, out.data()), "VecPlaceArray");
  const PetscErrorCode code = PCApply(p.pc, p.in, p.out);
  (void)VecResetArray(p.in);
  (void)VecResetArray(p.out);
  check_petsc(code, "PCApply");
}

int AmgPreconditioner::levels() const {
  PetscInt levels = 0;
  check_petsc(PCMGGetLevels(impl_->pc, &levels), "PCMGGetLevels");
  return static_cast<int>(levels);
}

}  // namespace mresim::mess
