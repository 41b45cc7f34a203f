#include "mresim/mess/magnetization/dipole_field.hpp"

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>
#include <utility>

namespace mresim::magnetism {

PairList OpenBoundary::pairs(const Eigen::Matrix3Xd& centres) const {
  const int n = static_cast<int>(centres.cols());
  PairList list;
  list.reserve(static_cast<std::size_t>(n) * static_cast<std::size_t>(n > 0 ? n - 1 : 0) / 2);
  for (int i = 0; i < n; ++i) {
    for (int j = i + 1; j < n; ++j) list.push_back({i, j, centres.col(i) - centres.col(j)});
  }
  return list;
}

Eigen::Matrix3d dipole_tensor(const Eigen::Vector3d& r, double volume) {
  const double distance = r.norm();
  if (!(std::isfinite(distance) && distance > 0.0)) {
    throw std::invalid_argument("dipole_tensor: particle centres coincide or are not finite");
  }
  const Eigen::Vector3d n = r / distance;
  const double scale = volume / (4.0 * std::numbers::pi * distance * distance * distance);
  // Eq. 4.57: V/(4 pi r^3) (3 n n^T - I).
  return scale * (3.0 * n * n.transpose() - Eigen::Matrix3d::Identity());
}

DipoleCoupling::DipoleCoupling(int particle_count, PairList pairs, double volume)
    : particle_count_(particle_count), pairs_(std::move(pairs)) {
  if (particle_count < 0) throw std::invalid_argument("DipoleCoupling: negative particle count");
  if (!(std::isfinite(volume) && volume > 0.0)) {
    throw std::invalid_argument("DipoleCoupling: particle volume must be finite and > 0");
  }
  tensors_.reserve(pairs_.size());
  for (const ParticlePair& p : pairs_) {
    if (p.i < 0 || p.j < 0 || p.i >= particle_count || p.j >= particle_count) {
      throw std::invalid_argument("DipoleCoupling: pair index out of range (" +
                                  std::to_string(p.i) + ", " + std::to_string(p.j) + ")");
    }
    tensors_.push_back(dipole_tensor(p.r, volume));
  }
}

DipoleCoupling DipoleCoupling::open(const Eigen::Matrix3Xd& centres, double volume) {
  return DipoleCoupling(static_cast<int>(centres.cols()), OpenBoundary{}.pairs(centres), volume);
}

Eigen::Matrix3Xd DipoleCoupling::field(const Eigen::Matrix3Xd& M) const {
  if (M.cols() != particle_count_) {
    throw std::invalid_argument("DipoleCoupling::field: magnetization has " +
                                std::to_string(M.cols()) + " columns, expected " +
                                std::to_string(particle_count_));
  }
  Eigen::Matrix3Xd H = Eigen::Matrix3Xd::Zero(3, particle_count_);
  for (std::size_t k = 0; k < pairs_.size(); ++k) {
    const ParticlePair& p = pairs_[k];
    const Eigen::Matrix3d& D = tensors_[k];
    // D is even in r: the field of j at i and of i at j use the same tensor. For a particle
    // and its own image (i == j) this adds 2 D M_i, the sum over the +-L image pair.
    H.col(p.i) += D * M.col(p.j);
    H.col(p.j) += D * M.col(p.i);
  }
  return H;
}

Eigen::MatrixXd DipoleCoupling::dense() const {
  const int n = 3 * particle_count_;
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(n, n);
  for (std::size_t k = 0; k < pairs_.size(); ++k) {
    const ParticlePair& p = pairs_[k];
    const Eigen::Index i = 3 * static_cast<Eigen::Index>(p.i);
    const Eigen::Index j = 3 * static_cast<Eigen::Index>(p.j);
    A.block<3, 3>(i, j) += tensors_[k];
    A.block<3, 3>(j, i) += tensors_[k];
  }
  return A;
}

Eigen::Matrix3Xd dipole_fields(const Eigen::Matrix3Xd& centres, const Eigen::Matrix3Xd& M,
                               double volume) {
  return DipoleCoupling::open(centres, volume).field(M);
}

}  // namespace mresim::magnetism
