// The L-BFGS two-loop recursion at full size: the minimiser's blocked, fused recursion
// (solvers/lbfgs_memory.hpp) on 1 and 2 threads against the textbook serial recursion with
// Eigen's vector algebra (what the minimiser used before), measured in one run.
//
// Problem: the free coordinates of the full-size Fig. 4.11 pair (3 x 284,592 unknowns; the held
// faces make the real count about 10 % smaller) and the default memory of 10 pairs, random
// pairs with positive curvature and a diagonal preconditioner, as in a relaxation. Printed:
// the best of the repeats for each variant, the ratios, the largest relative difference of
// the products (rounding only), and the load average (the machine is shared).
//
//   ./build/lbfgs_algebra_bench [--repeats 20] [--unknowns 853776]
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include "mresim/mess/solvers/lbfgs_memory.hpp"

namespace {

using mresim::mess::detail::LbfgsMemory;

Eigen::VectorXd random_vector(Eigen::Index n, std::mt19937_64& random) {
  std::normal_distribution<double> normal;
  Eigen::VectorXd v(n);
  for (Eigen::Index k = 0; k < n; ++k) v[k] = normal(random);
  return v;
}

// N&W Alg. 7.4 with Eigen's serial algebra.
Eigen::VectorXd serial_two_loop(const std::vector<Eigen::VectorXd>& s,
                                const std::vector<Eigen::VectorXd>& y, const Eigen::VectorXd& g,
                                const Eigen::VectorXd& p_diagonal, double scale) {
  Eigen::VectorXd q = g;
  std::vector<double> a(s.size());
  for (int k = static_cast<int>(s.size()) - 1; k >= 0; --k) {
    const auto i = static_cast<std::size_t>(k);
    a[i] = s[i].dot(q) / s[i].dot(y[i]);
    q -= a[i] * y[i];
  }
  q = p_diagonal.cwiseProduct(q) * scale;
  for (std::size_t i = 0; i < s.size(); ++i) {
    const double b = y[i].dot(q) / s[i].dot(y[i]);
    q += (a[i] - b) * s[i];
  }
  return q;
}

template <class F>
double best_ms(int repeats, F&& f) {
  double best = 1e300;
  for (int k = 0; k < repeats; ++k) {
    const auto start = std::chrono::steady_clock::now();
    f();
    best = std::min(
        best, std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                  .count());
  }
  return best;
}

}  // namespace

int main(int argc, char** argv) {
  int repeats = 20;
  Eigen::Index n = Eigen::Index{3} * 284592;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string key = argv[i];
    if (key == "--repeats") {
      repeats = std::max(1, std::atoi(argv[i + 1]));
    } else if (key == "--unknowns") {
      n = std::max<Eigen::Index>(1, std::atoll(argv[i + 1]));
    } else {
      std::fprintf(stderr, "lbfgs_algebra_bench: unknown option %s (--repeats, --unknowns)\n",
                   key.c_str());
      return 2;
    }
  }
  constexpr int kPairs = 10;
  std::mt19937_64 random(11);
  const Eigen::VectorXd curvature = random_vector(n, random).cwiseAbs().array() + 0.5;
  const Eigen::VectorXd p_diagonal = curvature.cwiseInverse();
  LbfgsMemory memory;
  std::vector<Eigen::VectorXd> s;
  std::vector<Eigen::VectorXd> y;
  for (int k = 0; k < kPairs; ++k) {
    const Eigen::VectorXd d = random_vector(n, random);
    const Eigen::VectorXd g_old = random_vector(n, random);
    const Eigen::VectorXd g_new = g_old + curvature.cwiseProduct(d);
    memory.add(1.0, d, g_new, g_old, kPairs);
    s.push_back(d);
    y.emplace_back(g_new - g_old);
  }
  const double scale = s.back().dot(y.back()) / y.back().dot(p_diagonal.cwiseProduct(y.back()));
  const Eigen::VectorXd g = random_vector(n, random);
  const LbfgsMemory::Preconditioner precondition = [&](const Eigen::VectorXd& v) {
    return Eigen::VectorXd(p_diagonal.cwiseProduct(v));
  };

  double load[1] = {0.0};
  (void)getloadavg(load, 1);
  std::printf("L-BFGS two-loop recursion: %lld unknowns, %d pairs, best of %d, load average %.2f\n",
              static_cast<long long>(n), kPairs, repeats, load[0]);
  const int threads_before = omp_get_max_threads();
  omp_set_num_threads(1);
  Eigen::VectorXd reference;
  const double serial =
      best_ms(repeats, [&] { reference = serial_two_loop(s, y, g, p_diagonal, scale); });
  Eigen::VectorXd product;
  const double blocked_1 = best_ms(repeats, [&] { product = memory.times(g, precondition); });
  const double difference = (product - reference).norm() / reference.norm();
  omp_set_num_threads(std::max(2, threads_before));
  const double blocked_2 = best_ms(repeats, [&] { product = memory.times(g, precondition); });
  std::printf("  serial, Eigen (1 thread)     %8.2f ms\n", serial);
  std::printf("  blocked, fused, 1 thread     %8.2f ms  (%.2fx against serial)\n", blocked_1,
              serial / blocked_1);
  std::printf(
      "  blocked, fused, %d threads    %8.2f ms  (%.2fx against serial, %.2fx against 1 "
      "thread)\n",
      std::max(2, threads_before), blocked_2, serial / blocked_2, blocked_1 / blocked_2);
  std::printf("  largest relative difference of the products: %.1e (rounding)\n", difference);
  return difference < 1e-10 ? 0 : 1;
}
