#pragma once

// Tools of preconditioned_spectrum_bench: the spectrum of a preconditioned operator from
// conjugate gradients (the Lanczos matrix of CG's coefficients), and additive corrections of a
// preconditioner that the bench tries (one more coarse space, one more exactly solved block).

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

namespace mresim::bench {

// What CG on H u = b with the preconditioner P tells about P H.
struct CgSpectrum {
  std::vector<int> iterations_to_decade;  // until ||r|| / ||b|| < 10^-d, d = 1, 2, ...
  Eigen::VectorXd ritz;                   // eigenvalues of the Lanczos matrix, ascending
  Eigen::MatrixXd basis;                  // the Lanczos vectors (columns; only if kept)
  Eigen::MatrixXd ritz_coefficients;      // eigenvectors of the Lanczos matrix

  // The j-th Ritz vector (an approximate eigenvector of P H); needs the kept basis.
  [[nodiscard]] Eigen::VectorXd ritz_vector(Eigen::Index j) const {
    return basis * ritz_coefficients.col(j);
  }
};

// Preconditioned CG from u = 0 for at most `steps` iterations (fewer once ||r|| / ||b|| < 1e-13).
// With keep_basis, keeps the Lanczos vectors (-1)^j z_j / sqrt(r_j . z_j) (n x steps doubles).
// The Lanczos matrix from CG's coefficients: Saad, Iterative Methods for Sparse Linear Systems,
// sec. 6.7.3.
template <class Hessian, class Preconditioner>
CgSpectrum cg_spectrum(const Hessian& hessian, const Preconditioner& precondition,
                       const Eigen::VectorXd& b, int steps, bool keep_basis) {
  CgSpectrum s;
  const Eigen::Index n = b.size();
  Eigen::VectorXd r = b;
  Eigen::VectorXd z = precondition(r);
  Eigen::VectorXd p = z;
  double rz = r.dot(z);
  std::vector<double> alphas;
  std::vector<double> betas;
  if (keep_basis) s.basis.resize(n, steps);
  const double b_norm = b.norm();
  int k = 0;
  while (k < steps) {
    if (keep_basis) s.basis.col(k) = (k % 2 == 0 ? 1.0 : -1.0) / std::sqrt(rz) * z;
    const Eigen::VectorXd hp = hessian(p);
    const double alpha = rz / p.dot(hp);
    r -= alpha * hp;
    alphas.push_back(alpha);
    ++k;
    const double relative = r.norm() / b_norm;
    while (s.iterations_to_decade.size() < 12 &&
           relative < std::pow(10.0, -static_cast<double>(s.iterations_to_decade.size() + 1))) {
      s.iterations_to_decade.push_back(k);
    }
    if (relative < 1e-13 || k == steps) break;
    z = precondition(r);
    const double rz_next = r.dot(z);
    betas.push_back(rz_next / rz);
    rz = rz_next;
    p = z + betas.back() * p;
  }
  Eigen::MatrixXd t = Eigen::MatrixXd::Zero(k, k);
  for (int j = 0; j < k; ++j) {
    const auto u = static_cast<std::size_t>(j);
    t(j, j) = 1.0 / alphas[u] + (j > 0 ? betas[u - 1] / alphas[u - 1] : 0.0);
    if (j + 1 < k) t(j, j + 1) = t(j + 1, j) = std::sqrt(betas[u]) / alphas[u];
  }
  if (keep_basis) s.basis.conservativeResize(n, k);
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(t);
  s.ritz = eig.eigenvalues();
  s.ritz_coefficients = eig.eigenvectors();
  return s;
}

// One line: the iterations to each decade and the ratio of the extreme Ritz values.
inline void print_cg_line(const std::string& label, const CgSpectrum& s) {
  std::printf("  %-68s", label.c_str());
  for (const int it : s.iterations_to_decade) std::printf(" %4d", it);
  std::printf("   (Ritz ratio %.4g)\n", s.ritz(s.ritz.size() - 1) / s.ritz(0));
}

// The pseudo-inverse of a symmetric matrix: eigenvalues at or below `floor` x the largest are
// dropped (0 in the inverse). `dropped`, if not null, counts them.
inline Eigen::MatrixXd positive_inverse(const Eigen::MatrixXd& m, double floor,
                                        Eigen::Index* dropped = nullptr) {
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(0.5 * (m + m.transpose()));
  const double top = eig.eigenvalues().maxCoeff();
  Eigen::VectorXd inverse = Eigen::VectorXd::Zero(m.rows());
  Eigen::Index count = 0;
  for (Eigen::Index j = 0; j < m.rows(); ++j) {
    if (eig.eigenvalues()(j) > floor * top) {
      inverse(j) = 1.0 / eig.eigenvalues()(j);
    } else {
      ++count;
    }
  }
  if (dropped != nullptr) *dropped = count;
  return eig.eigenvectors() * inverse.asDiagonal() * eig.eigenvectors().transpose();
}

// W (W^T H W)^+ W^T: the span of W's columns as one more coarse space, solved exactly with its
// Galerkin operator at the current state (added to a preconditioner, like the multilevel
// levels).
class CoarseSpace {
 public:
  template <class Hessian>
  CoarseSpace(Eigen::MatrixXd w, const Hessian& hessian) : w_(std::move(w)) {
    Eigen::MatrixXd hw(w_.rows(), w_.cols());
    for (Eigen::Index j = 0; j < w_.cols(); ++j) hw.col(j) = hessian(Eigen::VectorXd(w_.col(j)));
    galerkin_ = w_.transpose() * hw;
    inverse_ = positive_inverse(galerkin_, 1e-10);
  }
  [[nodiscard]] Eigen::VectorXd apply(const Eigen::VectorXd& v) const {
    return w_ * (inverse_ * (w_.transpose() * v));
  }
  [[nodiscard]] const Eigen::MatrixXd& w() const { return w_; }
  [[nodiscard]] const Eigen::MatrixXd& galerkin() const { return galerkin_; }

 private:
  Eigen::MatrixXd w_;
  Eigen::MatrixXd galerkin_;
  Eigen::MatrixXd inverse_;
};

// 1D piecewise-linear hats on the planes 0, stride, 2 stride, ... and n - 1 of a lattice axis
// of n planes: weights[j][i], hat j at plane i.
inline std::vector<std::vector<double>> hat_weights(int n, int stride) {
  std::vector<int> planes;
  for (int p = 0; p < n - 1; p += stride) planes.push_back(p);
  planes.push_back(n - 1);
  std::vector<std::vector<double>> w(planes.size(),
                                     std::vector<double>(static_cast<std::size_t>(n), 0.0));
  for (std::size_t j = 0; j + 1 < planes.size(); ++j) {
    for (int i = planes[j]; i <= planes[j + 1]; ++i) {
      const double t = static_cast<double>(i - planes[j]) / (planes[j + 1] - planes[j]);
      auto& lower = w[j][static_cast<std::size_t>(i)];
      lower = std::max(lower, 1.0 - t);
      w[j + 1][static_cast<std::size_t>(i)] = t;
    }
  }
  return w;
}

}  // namespace mresim::bench
