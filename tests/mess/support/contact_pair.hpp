#pragma once

// Two particles in a small held box for the preconditioner's tests (contact gaps, the cache).

#include <Eigen/Core>
#include <memory>

#include "mess_test_support.hpp"
#include "mresim/mess/system/constraints.hpp"
#include "mresim/mess/system/system_energy.hpp"
#include "multilevel_test_support.hpp"

namespace mresim::mess::testing {

// Two particles (n_d = 2, R = 2.5 l_e) `apart` cells apart along z in a 12 x 12 x 20 box, all
// faces held (physical profile), at rest.
struct ContactPair {
  explicit ContactPair(int apart, double field = 0.0)
      : sys(MessSystem::make(small_lattice(model_profile("physical"), {12, 12, 20},
                                           {{6, 6, 7}, {6, 6, 7 + apart}}, 2),
                             tesla(0.0, 0.0, field), model_profile("physical"))) {
    const lattice::Lattice& l = sys.lattice();
    sys.set_constraints(
        faces_held(l, {lattice::Face::left, lattice::Face::right, lattice::Face::front,
                       lattice::Face::back, lattice::Face::bottom, lattice::Face::top}));
    map = std::make_unique<DofMap>(sys.constraints(), l.positions, l.element_length);
  }
  // Every free coordinate moved by up to 0.05 l_e (fixed seed): the springs leave their rest
  // lengths, so the elastic Hessian differs from the stiffness terms the rest of P is built from.
  void perturb() {
    const double l_e = sys.lattice().element_length;
    Eigen::Matrix3Xd x = sys.positions();
    const Eigen::VectorXd shift = uniform_random_vector(3 * x.cols(), 21);
    for (Eigen::Index n = 0; n < x.cols(); ++n) {
      for (int a = 0; a < 3; ++a) {
        if (map->dof_of(n, a) >= 0) x(a, n) += 0.05 * l_e * shift[3 * n + a];
      }
    }
    sys.set_positions(x);
  }
  MessSystem sys;
  std::unique_ptr<DofMap> map;
};

}  // namespace mresim::mess::testing
