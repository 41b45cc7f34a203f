#include "mresim/mess/distributed/lattice_decomposition.hpp"

#include <petscdmda.h>

#include <algorithm>
#include <stdexcept>
#include <string>
#include <vector>

#include "mresim/mess/solvers/amg_preconditioner.hpp"

namespace mresim::mess {

void sum_in_rank_order(MPI_Comm comm, const double* local, double* total, int count) {
  int size = 1;
  MPI_Comm_size(comm, &size);
  std::vector<double> all(static_cast<std::size_t>(size) * static_cast<std::size_t>(count));
  if (MPI_Allgather(local, count, MPI_DOUBLE, all.data(), count, MPI_DOUBLE, comm) != MPI_SUCCESS) {
    throw std::runtime_error("sum_in_rank_order: MPI_Allgather failed");
  }
  for (int i = 0; i < count; ++i) {
    double sum = 0.0;
    for (int r = 0; r < size; ++r) {
      sum += all[static_cast<std::size_t>(r) * static_cast<std::size_t>(count) +
                 static_cast<std::size_t>(i)];
    }
    total[i] = sum;
  }
}

namespace {

// A DMDA box (i, j, k) = (iz, ix, iy) as a NodeBox in lattice coordinates.
NodeBox node_box(PetscInt i0, PetscInt j0, PetscInt k0, PetscInt ni, PetscInt nj, PetscInt nk) {
  NodeBox box;
  box.lower = {static_cast<int>(j0), static_cast<int>(k0), static_cast<int>(i0)};
  box.size = {static_cast<int>(nj), static_cast<int>(nk), static_cast<int>(ni)};
  return box;
}

}  // namespace

LatticeDecomposition::LatticeDecomposition(const lattice::GridShape& shape, MPI_Comm comm,
                                           std::array<int, 3> processes)
    : shape_(shape), comm_(comm) {
  lattice::validate_grid_shape(shape);
  for (const int p : processes) {
    if (p < 0) {
      throw std::invalid_argument("LatticeDecomposition: processes per axis must be >= 0, got " +
                                  std::to_string(p));
    }
  }
  initialise_petsc();
  int size = 1;
  MPI_Comm_size(comm, &size);
  const std::array<int, 3> nodes = shape.nodes;
  const bool fixed = processes[0] > 0 && processes[1] > 0 && processes[2] > 0;
  if ((fixed && processes[0] * processes[1] * processes[2] != size) ||
      !can_split(shape, size, processes)) {
    throw std::invalid_argument(
        "LatticeDecomposition: a grid of " + std::to_string(nodes[0]) + " x " +
        std::to_string(nodes[1]) + " x " + std::to_string(nodes[2]) +
        " nodes cannot be split over " + std::to_string(size) + " processes as " +
        std::to_string(processes[0]) + " x " + std::to_string(processes[1]) + " x " +
        std::to_string(processes[2]) + " (0: any; each process needs a node along every axis)");
  }
  const auto decide = [](int p) { return p == 0 ? PetscInt{PETSC_DECIDE} : PetscInt{p}; };
  check_petsc(DMDACreate3d(comm, DM_BOUNDARY_NONE, DM_BOUNDARY_NONE, DM_BOUNDARY_NONE,
                           DMDA_STENCIL_BOX, shape.nz(), shape.nx(), shape.ny(),
                           decide(processes[2]), decide(processes[0]), decide(processes[1]),
                           /*dof=*/3, /*stencil width=*/1, nullptr, nullptr, nullptr, &dm_),
              "DMDACreate3d");
  check_petsc(DMSetUp(dm_), "DMSetUp");
  PetscInt i0 = 0;
  PetscInt j0 = 0;
  PetscInt k0 = 0;
  PetscInt ni = 0;
  PetscInt nj = 0;
  PetscInt nk = 0;
  check_petsc(DMDAGetCorners(dm_, &i0, &j0, &k0, &ni, &nj, &nk), "DMDAGetCorners");
  owned_ = node_box(i0, j0, k0, ni, nj, nk);
  check_petsc(DMDAGetGhostCorners(dm_, &i0, &j0, &k0, &ni, &nj, &nk), "DMDAGetGhostCorners");
  ghosted_ = node_box(i0, j0, k0, ni, nj, nk);
}

bool LatticeDecomposition::can_split(const lattice::GridShape& shape, int size,
                                     std::array<int, 3> processes) {
  // Some px x py x pz = size with p_a <= nodes along a (and p_a as given where it is not 0).
  const auto fits = [&](int axis, int p) {
    const auto a = static_cast<std::size_t>(axis);
    return p <= shape.nodes[a] && (processes[a] == 0 || processes[a] == p);
  };
  for (int px = 1; px <= size; ++px) {
    if (size % px != 0 || !fits(0, px)) continue;
    for (int py = 1; py <= size / px; ++py) {
      if ((size / px) % py != 0 || !fits(1, py)) continue;
      if (fits(2, size / px / py)) return true;
    }
  }
  return false;
}

LatticeDecomposition::~LatticeDecomposition() {
  (void)VecScatterDestroy(&to_all_);
  (void)VecDestroy(&whole_);
  (void)VecDestroy(&natural_);
  (void)DMDestroy(&dm_);
}

Vec LatticeDecomposition::create_global_vector() const {
  Vec v = nullptr;
  check_petsc(DMCreateGlobalVector(dm_, &v), "DMCreateGlobalVector");
  return v;
}

void LatticeDecomposition::scatter(const Eigen::Matrix3Xd& all, Vec global) const {
  if (all.cols() != shape_.node_count()) {
    throw std::invalid_argument("LatticeDecomposition::scatter: expected " +
                                std::to_string(shape_.node_count()) + " columns, got " +
                                std::to_string(all.cols()));
  }
  PetscScalar* out = nullptr;
  check_petsc(VecGetArray(global, &out), "VecGetArray");
  const NodeBox& box = owned_;
  for (int iy = box.lower[1]; iy < box.lower[1] + box.size[1]; ++iy) {
    for (int ix = box.lower[0]; ix < box.lower[0] + box.size[0]; ++ix) {
      for (int iz = box.lower[2]; iz < box.lower[2] + box.size[2]; ++iz) {
        const std::int64_t k = box.offset(ix, iy, iz);
        const auto n = static_cast<Eigen::Index>(shape_.node_index(ix, iy, iz));
        for (int a = 0; a < 3; ++a) out[3 * k + a] = all(a, n);
      }
    }
  }
  check_petsc(VecRestoreArray(global, &out), "VecRestoreArray");
}

Eigen::Matrix3Xd LatticeDecomposition::gather(Vec global) const {
  // PETSc's natural order is the lattice's node order (see the header): global -> natural ->
  // a copy of the whole natural vector on every process. The vectors and the scatter are made
  // on first use and kept.
  if (natural_ == nullptr) {
    check_petsc(DMDACreateNaturalVector(dm_, &natural_), "DMDACreateNaturalVector");
    check_petsc(VecScatterCreateToAll(natural_, &to_all_, &whole_), "VecScatterCreateToAll");
  }
  check_petsc(DMDAGlobalToNaturalBegin(dm_, global, INSERT_VALUES, natural_),
              "DMDAGlobalToNaturalBegin");
  check_petsc(DMDAGlobalToNaturalEnd(dm_, global, INSERT_VALUES, natural_),
              "DMDAGlobalToNaturalEnd");
  check_petsc(VecScatterBegin(to_all_, natural_, whole_, INSERT_VALUES, SCATTER_FORWARD),
              "VecScatterBegin");
  check_petsc(VecScatterEnd(to_all_, natural_, whole_, INSERT_VALUES, SCATTER_FORWARD),
              "VecScatterEnd");
  Eigen::Matrix3Xd all(3, shape_.node_count());
  const PetscScalar* values = nullptr;
  check_petsc(VecGetArrayRead(whole_, &values), "VecGetArrayRead");
  std::copy(values, values + all.size(), all.data());
  check_petsc(VecRestoreArrayRead(whole_, &values), "VecRestoreArrayRead");
  return all;
}

}  // namespace mresim::mess
