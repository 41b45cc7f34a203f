#pragma once

#include <vector>

namespace mresim::cli {

// The MPI job a process belongs to, for `mpirun -np N mresim sweep ...`: MPI is initialised
// only when the process was started by an MPI launcher (it sets OMPI_COMM_WORLD_SIZE, PMIX_RANK
// or PMI_SIZE), so a plain `mresim sweep` needs no mpirun and is a job of one rank. Finalises
// MPI when destroyed. Only the sweep command uses it; each point runs as a separate process.
class MpiWorld {
 public:
  MpiWorld();
  ~MpiWorld();
  MpiWorld(const MpiWorld&) = delete;
  MpiWorld& operator=(const MpiWorld&) = delete;
  MpiWorld(MpiWorld&&) = delete;
  MpiWorld& operator=(MpiWorld&&) = delete;

  [[nodiscard]] int rank() const { return rank_; }
  [[nodiscard]] int size() const { return size_; }
  // The ranks on this machine (OpenMPI's OMPI_COMM_WORLD_LOCAL_SIZE; else 1), to share its cores.
  [[nodiscard]] int local_size() const { return local_size_; }

  // Rank 0's `value` on every rank.
  [[nodiscard]] int broadcast(int value) const;
  // The element-wise sum over all ranks, on rank 0 (other ranks get their own values back).
  [[nodiscard]] std::vector<int> sum_on_root(const std::vector<int>& values) const;

 private:
  bool initialised_ = false;
  int rank_ = 0;
  int size_ = 1;
  int local_size_ = 1;
};

}  // namespace mresim::cli
