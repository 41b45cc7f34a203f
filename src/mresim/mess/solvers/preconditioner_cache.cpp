#include "mresim/mess/solvers/preconditioner_cache.hpp"

#include <bit>
#include <cmath>

#include "mresim/mess/solvers/contact_gap_blocks.hpp"

namespace mresim::mess {

namespace {

// FNV-1a over what a preconditioner depends on besides the lattice.
class Fingerprint {
 public:
  void add(std::uint64_t value) {
    for (int byte = 0; byte < 8; ++byte) {
      hash_ ^= (value >> (8 * byte)) & 0xffU;
      hash_ *= 0x100000001b3ULL;
    }
  }
  std::uint64_t value() const { return hash_; }

 private:
  std::uint64_t hash_ = 0xcbf29ce484222325ULL;
};

std::uint64_t preconditioner_key(const MessSystem& system, const DofMap& map, double force_scale,
                                 bool multilevel) {
  Fingerprint f;
  f.add(multilevel ? 1U : 0U);
  f.add(std::bit_cast<std::uint64_t>(force_scale));
  f.add(std::bit_cast<std::uint64_t>(system.settings().elastic.volume_force_factor));
  f.add(static_cast<std::uint64_t>(map.size()));
  for (Eigen::Index k = 0; k < map.own_dofs(); ++k) {
    f.add(static_cast<std::uint64_t>(map.coordinate_of(k)));
  }
  for (Eigen::Index g = 0; g < map.groups(); ++g) {
    f.add(static_cast<std::uint64_t>(map.group_nodes(g).size()));
    for (const std::int32_t n : map.group_nodes(g)) f.add(static_cast<std::uint64_t>(n));
  }
  return f.value();
}

}  // namespace

std::shared_ptr<const RigidParticlePreconditioner> PreconditionerCache::get(
    const MessSystem& system, const DofMap& map, double force_scale, bool multilevel,
    const detail::BlockSplit* processes, NodeScaling node_scaling, ContactGap contact_gap,
    double reuse_distance) {
  const std::uint64_t key = preconditioner_key(system, map, force_scale, multilevel);
  if (multilevel) {
    return get_multilevel(system, map, force_scale, processes, node_scaling, contact_gap,
                          reuse_distance, key);
  }
  if (kept_ == nullptr || lattice_ != &system.lattice() || key != key_) {
    kept_.reset();
    anchor_.reset();
    kept_ =
        std::make_shared<const RigidParticlePreconditioner>(system, map, force_scale, multilevel);
    lattice_ = &system.lattice();
    key_ = key;
    ++builds_;
  }
  return kept_;
}

std::shared_ptr<const RigidParticlePreconditioner> PreconditionerCache::get_multilevel(
    const MessSystem& system, const DofMap& map, double force_scale,
    const detail::BlockSplit* processes, NodeScaling node_scaling, ContactGap contact_gap,
    double reuse_distance, std::uint64_t key) {
  last_kept_ = reuse_distance > 0.0 && close_to_anchor(system, reuse_distance, key);
  if (last_kept_ && kept_ != nullptr) return kept_;
  kept_.reset();  // before the new one is built: never two at once
  if (!last_kept_) {
    anchor_.reset();
    if (reuse_distance > 0.0) {
      anchor_ = std::make_shared<const PreconditionerAnchor>(
          PreconditionerAnchor{system.positions().cast<float>(), key});
    }
  }
  // At the anchor's positions where there is one (header); else at the exact ones.
  const Eigen::Matrix3Xd* at = &system.positions();
  Eigen::Matrix3Xd rounded;
  if (anchor_ != nullptr) {
    rounded = anchor_->positions.cast<double>();
    at = &rounded;
  }
  kept_ = std::make_shared<const RigidParticlePreconditioner>(system, map, force_scale, true, at,
                                                              processes, node_scaling, contact_gap);
  lattice_ = &system.lattice();
  key_ = key;
  ++builds_;
  return kept_;
}

bool PreconditionerCache::close_to_anchor(const MessSystem& system, double reuse_distance,
                                          std::uint64_t key) const {
  const Eigen::Matrix3Xd& x = system.positions();
  if (anchor_ == nullptr || anchor_->positions.cols() != x.cols() || anchor_->key != key ||
      lattice_ != &system.lattice()) {
    return false;
  }
  const Eigen::Matrix3Xf& a = anchor_->positions;
  const double limit = reuse_distance * system.lattice().element_length;
  for (Eigen::Index n = 0; n < x.cols(); ++n) {
    if ((x.col(n) - a.col(n).cast<double>()).norm() > limit) return false;
  }
  // The pairs in contact at the anchor: its particles' centres (the mean of their nodes).
  const lattice::Lattice& lat = system.lattice();
  Eigen::Matrix3Xd centres(3, static_cast<Eigen::Index>(lat.particle_nodes.size()));
  for (Eigen::Index p = 0; p < centres.cols(); ++p) {
    const auto& nodes = lat.particle_nodes[static_cast<std::size_t>(p)];
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (const std::int32_t n : nodes) sum += a.col(n).cast<double>();
    centres.col(p) = sum / static_cast<double>(nodes.size());
  }
  const double radius = lat.particle_radius;
  return ContactGapBlocks::contact_pairs(centres, radius) ==
         ContactGapBlocks::contact_pairs(system.particle_centres(CentreRule::all_nodes), radius);
}

void PreconditionerCache::restore(const lattice::Lattice& lattice,
                                  std::shared_ptr<const PreconditionerAnchor> anchor) {
  kept_.reset();
  lattice_ = &lattice;
  anchor_ = std::move(anchor);
  last_kept_ = false;
}

}  // namespace mresim::mess
