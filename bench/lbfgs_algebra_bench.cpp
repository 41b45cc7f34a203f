// L-BFGS's product with the inverse-Hessian approximation at full size: the minimiser's
// compact-form product (solvers/lbfgs_memory.hpp) on 1 and 2 threads against the textbook serial
// two-loop recursion with Eigen's vector algebra, and the same product with the pairs stored in
// single precision (LbfgsPrecision::single_precision, the default with the multilevel
// preconditioner), measured in one run; then L-BFGS's order of a pair and a product, with the
// preconditioner's applications counted (one per iteration; the two-loop recursion needed two:
// P q, and P y of the newest pair for H0's scale).
//
// Problem: the free coordinates of the full-size Fig. 4.11 pair (3 x 284,592 unknowns; the held
// faces make the real count about 10 % smaller) and the default memory of 10 pairs, random
// pairs with positive curvature and a diagonal preconditioner, as in a relaxation. Printed:
// the best of the repeats for each variant, the ratios, the largest relative difference of
// the products (rounding only; for single precision the rounding of the stored pairs), the
// pairs' bytes per node, and the load average (the machine is shared).
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
using mresim::mess::detail::LbfgsPrecision;

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

// L-BFGS's order on a quadratic: a product at g, the pair to the next point, a product there,
// ... with the pairs in single precision. Prints the preconditioner's applications and the best
// time of adding a pair and of a product; true if P was applied once per product.
bool lbfgs_order(int iterations, int pairs, const Eigen::VectorXd& curvature,
                 const Eigen::VectorXd& p_diagonal, std::mt19937_64& random) {
  LbfgsMemory memory;
  memory.set_precision(LbfgsPrecision::single_precision);
  int applications = 0;
  const LbfgsMemory::Preconditioner counted = [&](const Eigen::VectorXd& v) {
    ++applications;
    return Eigen::VectorXd(p_diagonal.cwiseProduct(v));
  };
  Eigen::VectorXd at = random_vector(curvature.size(), random);
  Eigen::VectorXd step = -memory.times(at, counted);
  double add_ms = 1e300;
  double product_ms = 1e300;
  const auto since = [](std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
        .count();
  };
  for (int k = 0; k < iterations; ++k) {
    const Eigen::VectorXd next = at + curvature.cwiseProduct(0.5 * step);
    auto start = std::chrono::steady_clock::now();
    memory.add(0.5, step, next, at, pairs);
    add_ms = std::min(add_ms, since(start));
    at = next;
    start = std::chrono::steady_clock::now();
    step = -memory.times(at, counted);
    product_ms = std::min(product_ms, since(start));
  }
  std::printf(
      "  L-BFGS's order, %d iterations (pairs in single precision, %d threads): %d applications "
      "of P (the two-loop recursion: %d); best of each: adding the pair %.2f ms, the product "
      "%.2f ms\n",
      iterations, omp_get_max_threads(), applications, 2 * iterations + 1, add_ms, product_ms);
  return applications == iterations + 1;
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
  LbfgsMemory single;
  single.set_precision(LbfgsPrecision::single_precision);
  std::vector<Eigen::VectorXd> s;
  std::vector<Eigen::VectorXd> y;
  for (int k = 0; k < kPairs; ++k) {
    const Eigen::VectorXd d = random_vector(n, random);
    const Eigen::VectorXd g_old = random_vector(n, random);
    const Eigen::VectorXd g_new = g_old + curvature.cwiseProduct(d);
    memory.add(1.0, d, g_new, g_old, kPairs);
    single.add(1.0, d, g_new, g_old, kPairs);
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
  std::printf("L-BFGS product: %lld unknowns, %d pairs, best of %d, load average %.2f\n",
              static_cast<long long>(n), kPairs, repeats, load[0]);
  const int threads_before = omp_get_max_threads();
  omp_set_num_threads(1);
  Eigen::VectorXd reference;
  const double serial =
      best_ms(repeats, [&] { reference = serial_two_loop(s, y, g, p_diagonal, scale); });
  Eigen::VectorXd product;
  const double blocked_1 = best_ms(repeats, [&] { product = memory.times(g, precondition); });
  const double difference = (product - reference).norm() / reference.norm();
  Eigen::VectorXd single_product;
  const double single_1 = best_ms(repeats, [&] { single_product = single.times(g, precondition); });
  const double single_difference = (single_product - reference).norm() / reference.norm();
  omp_set_num_threads(std::max(2, threads_before));
  const double blocked_2 = best_ms(repeats, [&] { product = memory.times(g, precondition); });
  const double single_2 = best_ms(repeats, [&] { single_product = single.times(g, precondition); });
  std::printf("  two-loop, serial, Eigen (1 thread)  %8.2f ms\n", serial);
  std::printf("  compact form, 1 thread             %8.2f ms  (%.2fx against serial)\n", blocked_1,
              serial / blocked_1);
  std::printf(
      "  compact form, %d threads            %8.2f ms  (%.2fx against serial, %.2fx against 1 "
      "thread)\n",
      std::max(2, threads_before), blocked_2, serial / blocked_2, blocked_1 / blocked_2);
  std::printf("  largest relative difference of the products: %.1e (rounding)\n", difference);
  const double nodes = static_cast<double>(n) / 3.0;
  std::printf("  pairs in single precision, 1 thread   %8.2f ms  (%.2fx against double)\n",
              single_1, blocked_1 / single_1);
  std::printf("  pairs in single precision, %d threads  %8.2f ms  (%.2fx against double)\n",
              std::max(2, threads_before), single_2, blocked_2 / single_2);
  std::printf("  pairs' bytes per node: %.0f in double, %.0f in single precision\n",
              static_cast<double>(memory.stored_bytes()) / nodes,
              static_cast<double>(single.stored_bytes()) / nodes);
  std::printf("  single precision against the serial product: %.1e (the pairs' rounding)\n",
              single_difference);

  const int iterations = 12;
  const bool one_application = lbfgs_order(iterations, kPairs, curvature, p_diagonal, random);
  return difference < 1e-10 && single_difference < 1e-5 && one_application ? 0 : 1;
}
