#pragma once

// Helpers of the multilevel correction's tests (tests/mess/solvers/multilevel_correction_test.cpp
// and, over MPI processes, tests/mess/distributed/distributed_multilevel_test.cpp).

#include <Eigen/Core>
#include <initializer_list>
#include <random>

#include "mresim/mess/lattice/lattice.hpp"
#include "mresim/mess/solvers/multilevel_correction.hpp"
#include "mresim/mess/system/constraints.hpp"

namespace mresim::mess::testing {

// n entries drawn uniformly from [-1, 1), the same for the same seed.
inline Eigen::VectorXd uniform_random_vector(Eigen::Index n, unsigned seed) {
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::VectorXd v(n);
  for (Eigen::Index i = 0; i < n; ++i) v[i] = u(gen);
  return v;
}

// C v over the map's dofs.
inline Eigen::VectorXd apply_correction(const mess::MultilevelCorrection& c,
                                        const mess::DofMap& map, const Eigen::VectorXd& v) {
  Eigen::VectorXd w = Eigen::VectorXd::Zero(v.size());
  c.add_to(map, v, w);
  return w;
}

// Every node of the given faces held where the lattice put it.
inline mess::BoundaryConstraints faces_held(const lattice::Lattice& l,
                                            std::initializer_list<lattice::Face> faces) {
  mess::BoundaryConstraints c = mess::BoundaryConstraints::none(l.node_count());
  for (const lattice::Face f : faces) c.fix_face(l.shape, f, l.positions);
  return c;
}

}  // namespace mresim::mess::testing
