#include "mresim/mess/terms/grid_stencil.hpp"

#include <algorithm>
#include <numeric>
#include <stdexcept>
#include <string>

namespace mresim::mess {

std::array<std::int64_t, 13> forward_offset_deltas(const lattice::GridShape& shape) {
  std::array<std::int64_t, 13> delta{};
  for (std::size_t o = 0; o < delta.size(); ++o) {
    const auto& d = lattice::kForwardNeighbours[o];
    delta[o] = d[2] + std::int64_t{shape.nz()} * (d[0] + std::int64_t{shape.nx()} * d[1]);
  }
  return delta;
}

std::array<int, 13> backward_offset_order(const std::array<std::int64_t, 13>& deltas) {
  std::array<int, 13> order{};
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    return deltas[static_cast<std::size_t>(a)] > deltas[static_cast<std::size_t>(b)];
  });
  return order;
}

SpringStencil::SpringStencil(const lattice::Lattice& lattice) : shape_(lattice.shape) {
  const int nx = shape_.nx();
  const int ny = shape_.ny();
  const int nz = shape_.nz();
  delta_ = forward_offset_deltas(shape_);
  backward_order_ = backward_offset_order(delta_);
  // Number of bits set in every 13-bit mask (spring_of's rank of an offset).
  bits_set_.resize(std::size_t{1} << delta_.size());
  for (std::size_t mask = 1; mask < bits_set_.size(); ++mask) {
    bits_set_[mask] = static_cast<std::uint8_t>(bits_set_[mask >> 1U] + (mask & 1U));
  }

  // Present offsets per node, and a check that the spring set is numbered as the stencil says.
  const lattice::SpringSet& springs = lattice.springs;
  const std::int64_t nodes = shape_.node_count();
  first_spring_.resize(static_cast<std::size_t>(nodes));
  mask_.resize(static_cast<std::size_t>(nodes));
  std::size_t s = 0;
  for (std::int64_t n = 0; n < nodes; ++n) {
    const std::array<int, 3> c = shape_.node_coordinates(static_cast<int>(n));
    first_spring_[static_cast<std::size_t>(n)] = static_cast<std::int64_t>(s);
    unsigned mask = 0;
    for (std::size_t o = 0; o < delta_.size(); ++o) {
      const auto& d = lattice::kForwardNeighbours[o];
      const int jx = c[0] + d[0];
      const int jy = c[1] + d[1];
      const int jz = c[2] + d[2];
      if (jx < 0 || jx >= nx || jy < 0 || jy >= ny || jz < 0 || jz >= nz) continue;
      if (s >= springs.size() || springs.first[s] != n || springs.second(s) != n + delta_[o]) {
        throw std::invalid_argument("SpringStencil: spring " + std::to_string(s) +
                                    " is not the forward-neighbour spring of node " +
                                    std::to_string(n) + " the stencil expects");
      }
      mask |= 1U << o;
      ++s;
    }
    mask_[static_cast<std::size_t>(n)] = static_cast<std::uint16_t>(mask);
  }
  spring_count_ = static_cast<std::int64_t>(s);
  if (s != springs.size()) {
    throw std::invalid_argument("SpringStencil: the lattice has " + std::to_string(springs.size()) +
                                " springs, its grid " + std::to_string(s));
  }
}

}  // namespace mresim::mess
