#pragma once

// A run's preconditioner for the minimisers (preconditioner.hpp), kept across its relaxations.
//
// Without the multilevel correction P is built at rest and rebuilt only when what it depends on
// changes (the free coordinates and rigid groups, the force scale, the multilevel choice).
//
// With it, P is built at a state: the start of the relaxation that asks. Building it costs about
// 3.4 s on the full-size Fig. 4.11 lattice in contact (the coarse levels 2.1 s, the gap between
// the particles 1.1 s), a third of a typical field step in contact there, while a step in
// contact moves the lattice by about 0.02 lattice spacings. So a relaxation keeps the P built
// at an earlier start while the state stays close to it (`reuse_distance`, solver
// .preconditioner_reuse):
//
//   kept  <=>  max_n |x_n - a_n| <= reuse_distance l_e  and  the same particle pairs in contact
//              (ContactGapBlocks::contact_pairs)  and  the same free coordinates (key),
//
// x the positions now and a the anchor: the positions P was built at. P only steers L-BFGS
// (its initial inverse Hessian), so the state a relaxation converges to is the same within the
// solver's tolerance either way; the pairs condition rebuilds P when a gap opens or closes.
// On the full-size Fig. 4.11 loop with reuse_distance 0.1 the iterations were those of a build
// at every start (12,978 against 13,022) and 34 of 61 steps kept P (docs/performance.md,
// "Keeping the multilevel preconditioner between steps"). The default is 0.3: between two
// fields at one strain the helix's lattice moves 0.15-0.32 spacings, so with 0.1 it built P
// at 131 of 132 steps; with 0.3 one strain value ran 1.18x faster and the Fig. 4.11 loop
// 1.09x, the states the same to 2e-14 m ("Routes measured for the helix's remaining 1.7x").
//
// The anchor is kept in single precision (12 bytes per node), and with reuse_distance > 0 P is
// built at the anchor's positions rounded so, not at x itself: the anchor then describes P
// completely, and a run resumed from a checkpoint that holds it (anchor(), restore()) builds the
// same P, bit for bit, where the uninterrupted run had kept one. reuse_distance = 0: a new P at
// every request at the exact positions, no anchor (the behaviour before the reuse).
//
// Only one P is held at a time: the kept one is released before a new one is built (peak
// memory).

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

#include "mresim/mess/solvers/preconditioner.hpp"

namespace mresim::mess {

// Where the kept multilevel preconditioner was built (see above).
struct PreconditionerAnchor {
  Eigen::Matrix3Xf positions;  // m, 3 x N
  std::uint64_t key = 0;       // the free coordinates, force scale, ... it was built for
};

class PreconditionerCache {
 public:
  // The preconditioner for these arguments (see above); `processes`, `node_scaling` and
  // `contact_gap` as for RigidParticlePreconditioner's constructor. `reuse_distance`: in
  // lattice spacings, >= 0 (only read with `multilevel`).
  std::shared_ptr<const RigidParticlePreconditioner> get(
      const MessSystem& system, const DofMap& map, double force_scale, bool multilevel,
      const detail::BlockSplit* processes = nullptr, NodeScaling node_scaling = NodeScaling::blocks,
      ContactGap contact_gap = ContactGap::exact, double reuse_distance = 0.0);

  // Preconditioners built so far.
  [[nodiscard]] int builds() const { return builds_; }
  // Whether the last get() with the multilevel correction handed out a kept one.
  [[nodiscard]] bool last_kept() const { return last_kept_; }

  // The anchor of the kept multilevel preconditioner (null: none), for checkpoints.
  [[nodiscard]] const std::shared_ptr<const PreconditionerAnchor>& anchor() const {
    return anchor_;
  }
  // Takes over the anchor a run had after some step, on this lattice (a resumed or extended
  // run: checkpoints), and releases the kept preconditioner. The next get() decides as that run
  // did and builds at the anchor where it would have kept P. Null: no anchor (the next get()
  // builds at the state).
  void restore(const lattice::Lattice& lattice, std::shared_ptr<const PreconditionerAnchor> anchor);

 private:
  std::shared_ptr<const RigidParticlePreconditioner> get_multilevel(
      const MessSystem& system, const DofMap& map, double force_scale,
      const detail::BlockSplit* processes, NodeScaling node_scaling, ContactGap contact_gap,
      double reuse_distance, std::uint64_t key);
  // Whether the state x may keep the anchor's P (see above).
  bool close_to_anchor(const MessSystem& system, double reuse_distance, std::uint64_t key) const;

  std::shared_ptr<const RigidParticlePreconditioner> kept_;
  const lattice::Lattice* lattice_ = nullptr;
  std::uint64_t key_ = 0;
  int builds_ = 0;
  bool last_kept_ = false;
  std::shared_ptr<const PreconditionerAnchor> anchor_;
};

}  // namespace mresim::mess
