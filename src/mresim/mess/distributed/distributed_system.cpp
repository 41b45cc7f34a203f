#include "mresim/mess/distributed/distributed_system.hpp"

#include <algorithm>
#include <array>
#include <stdexcept>
#include <string>
#include <string_view>

namespace mresim::mess {

namespace {

namespace mm = mresim::magnetism;

// The terms evaluated here: the elastic ones on each process's nodes, the load as a sum over
// them, and the terms of the particle centres and magnetizations only, on every process
// (field_gradient, eq. 4.77's Kelvin force, is one of those: terms/field_gradient_term.cpp).
constexpr std::array<std::string_view, 9> kSupportedTerms = {"springs", "volume", "zeeman",
                                                             "dipole",  "self",   "self_linearized",
                                                             "wca",     "load",   "field_gradient"};

void check_supported(std::string_view name) {
  if (DistributedSystem::supports(name)) return;
  throw std::invalid_argument("DistributedSystem: the energy term '" + std::string(name) +
                              "' cannot be evaluated over processes yet (supported: springs, "
                              "volume, zeeman, dipole, self, self_linearized, wca, load, "
                              "field_gradient)");
}

void check_mpi(int code, const char* what) {
  if (code != MPI_SUCCESS) throw std::runtime_error(std::string("DistributedSystem: ") + what);
}

}  // namespace

bool DistributedSystem::supports(std::string_view term) {
  return std::find(kSupportedTerms.begin(), kSupportedTerms.end(), term) != kSupportedTerms.end();
}

DistributedSystem::DistributedSystem(MessSystem& system, const LatticeDecomposition& decomposition)
    : system_(system),
      decomposition_(decomposition),
      elastic_(system.lattice(), decomposition, system.settings().elastic.volume_force_factor) {
  for (const auto& t : system.terms()) check_supported(t->name());

  // The owned particle nodes: their slots in the concatenated particle-node list.
  const lattice::Lattice& lattice = system.lattice();
  const NodeBox& owned = decomposition.owned();
  std::int64_t slot = 0;
  for (std::size_t p = 0; p < lattice.particle_count(); ++p) {
    for (const std::int32_t n : lattice.particle_nodes[p]) {
      const std::array<int, 3> c = lattice.shape.node_coordinates(n);
      if (owned.contains(c[0], c[1], c[2])) {
        owned_particle_slots_.push_back(slot);
        owned_particle_offsets_.push_back(owned.offset(c[0], c[1], c[2]));
        owned_particle_of_.push_back(static_cast<std::int32_t>(p));
      }
      ++slot;
    }
  }
  particle_node_total_ = slot;

  // Every process's share, and the slots in the order they arrive.
  int size = 1;
  MPI_Comm_size(decomposition.comm(), &size);
  const int mine = static_cast<int>(owned_particle_slots_.size());
  std::vector<int> nodes_of(static_cast<std::size_t>(size), 0);
  check_mpi(MPI_Allgather(&mine, 1, MPI_INT, nodes_of.data(), 1, MPI_INT, decomposition.comm()),
            "MPI_Allgather");
  std::vector<int> node_displacements(nodes_of.size(), 0);
  particle_counts_.resize(nodes_of.size());
  particle_displacements_.resize(nodes_of.size());
  for (std::size_t r = 0; r < nodes_of.size(); ++r) {
    if (r > 0) node_displacements[r] = node_displacements[r - 1] + nodes_of[r - 1];
    particle_counts_[r] = 3 * nodes_of[r];
    particle_displacements_[r] = 3 * node_displacements[r];
  }
  gathered_slots_.resize(static_cast<std::size_t>(particle_node_total_));
  check_mpi(
      MPI_Allgatherv(owned_particle_slots_.data(), mine, MPI_INT64_T, gathered_slots_.data(),
                     nodes_of.data(), node_displacements.data(), MPI_INT64_T, decomposition.comm()),
      "MPI_Allgatherv");
}

Eigen::Matrix3Xd DistributedSystem::gather_particle_nodes(
    const PetscScalar* owned_positions) const {
  std::vector<double> mine(3 * owned_particle_offsets_.size());
  for (std::size_t i = 0; i < owned_particle_offsets_.size(); ++i) {
    std::copy_n(owned_positions + 3 * owned_particle_offsets_[i], 3, mine.data() + 3 * i);
  }
  std::vector<double> all(static_cast<std::size_t>(3 * particle_node_total_));
  check_mpi(MPI_Allgatherv(mine.data(), static_cast<int>(mine.size()), MPI_DOUBLE, all.data(),
                           particle_counts_.data(), particle_displacements_.data(), MPI_DOUBLE,
                           decomposition_.comm()),
            "MPI_Allgatherv");
  Eigen::Matrix3Xd nodes(3, particle_node_total_);
  for (std::size_t i = 0; i < gathered_slots_.size(); ++i) {
    nodes.col(gathered_slots_[i]) = Eigen::Map<const Eigen::Vector3d>(all.data() + 3 * i);
  }
  return nodes;
}

Evaluation DistributedSystem::evaluate(Vec positions, Vec gradient) {
  const lattice::Lattice& lattice = system_.lattice();
  const MessSettings& settings = system_.settings();
  if (settings.elastic.volume_force_factor != elastic_.volume_force_factor()) {
    throw std::invalid_argument(
        "DistributedSystem: volume_force_factor changed since the evaluator was built");
  }
  const NodeBox& owned = decomposition_.owned();
  const PetscScalar* x = nullptr;
  check_petsc(VecGetArrayRead(positions, &x), "VecGetArrayRead");

  // Particle centres as MessSystem::particle_centres computes them (the first 8 nodes of a
  // particle are its centre voxel's corners), then M by the system's update rule.
  const Eigen::Matrix3Xd particle_nodes = gather_particle_nodes(x);
  const auto np = static_cast<Eigen::Index>(lattice.particle_count());
  centres_.resize(3, np);
  Eigen::Index slot = 0;
  for (Eigen::Index p = 0; p < np; ++p) {
    const auto& nodes = lattice.particle_nodes[static_cast<std::size_t>(p)];
    const std::size_t count = settings.centre_rule == CentreRule::centre_voxel ? 8 : nodes.size();
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (std::size_t k = 0; k < count; ++k) {
      sum += particle_nodes.col(slot + static_cast<Eigen::Index>(k));
    }
    centres_.col(p) = sum / static_cast<double>(count);
    slot += static_cast<Eigen::Index>(nodes.size());
  }
  system_.update_magnetization_at(centres_);

  // The elastic terms write the owned gradient; the other terms follow in list order.
  const ElasticEnergies elastic = elastic_.evaluate(positions, gradient);
  const mm::PairList pairs = np > 0 ? mm::OpenBoundary{}.pairs(centres_) : mm::PairList{};
  const Eigen::Matrix3Xd no_nodes(3, 0);  // the centre terms do not read node positions
  const TermState state{lattice,         no_nodes, centres_, system_.magnetizations(),
                        system_.model(), no_nodes, settings, pairs};
  TermGradient centre_gradient{no_nodes, Eigen::Matrix3Xd::Zero(3, np)};
  const Eigen::Matrix3Xd& forces = system_.applied_forces();
  const Eigen::Matrix3Xd& x0 = lattice.positions;
  PetscScalar* g = nullptr;
  if (gradient != nullptr) check_petsc(VecGetArray(gradient, &g), "VecGetArray");
  const auto& terms = system_.terms();
  std::vector<TermValue> values(terms.size());
  for (std::size_t i = 0; i < terms.size(); ++i) {
    const EnergyTerm& t = *terms[i];
    if (t.name() == "springs") {
      values[i] = {elastic.springs, elastic.springs_rounding};
    } else if (t.name() == "volume") {
      values[i] = {elastic.volume, elastic.volume_rounding};
    } else if (t.name() == "load") {
      if (forces.cols() == 0) continue;
      // -sum f.(x - x0) over the owned nodes (gradient -f), summed over the processes.
      double work = 0.0;
      for (int iy = owned.lower[1]; iy < owned.lower[1] + owned.size[1]; ++iy) {
        for (int ix = owned.lower[0]; ix < owned.lower[0] + owned.size[0]; ++ix) {
          for (int iz = owned.lower[2]; iz < owned.lower[2] + owned.size[2]; ++iz) {
            const auto n = static_cast<Eigen::Index>(lattice.shape.node_index(ix, iy, iz));
            const std::int64_t k = owned.offset(ix, iy, iz);
            const Eigen::Map<const Eigen::Vector3d> xn(x + 3 * k);
            work += forces.col(n).dot(xn - x0.col(n));
            if (g != nullptr) {
              Eigen::Map<Eigen::Vector3d> gn(g + 3 * k);
              gn -= forces.col(n);
            }
          }
        }
      }
      double total = 0.0;
      sum_in_rank_order(decomposition_.comm(), &work, &total, 1);
      values[i] = {-total, 0.0};
    } else {
      values[i] =
          t.evaluate(state, t.in_total() && gradient != nullptr ? &centre_gradient : nullptr);
    }
  }
  // Each particle's centre gradient shared equally by its nodes (MessSystem::evaluate).
  if (g != nullptr) {
    for (std::size_t i = 0; i < owned_particle_offsets_.size(); ++i) {
      const auto p = static_cast<std::size_t>(owned_particle_of_[i]);
      const Eigen::Vector3d share = centre_gradient.centres.col(static_cast<Eigen::Index>(p)) /
                                    static_cast<double>(lattice.particle_nodes[p].size());
      Eigen::Map<Eigen::Vector3d>(g + 3 * owned_particle_offsets_[i]) += share;
    }
    check_petsc(VecRestoreArray(gradient, &g), "VecRestoreArray");
  }
  check_petsc(VecRestoreArrayRead(positions, &x), "VecRestoreArrayRead");
  return evaluation_from_terms(terms, system_.energy_labels(), values, state);
}

}  // namespace mresim::mess
