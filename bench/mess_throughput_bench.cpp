// Throughput of one energy + gradient evaluation of the 3D model at full size, printed next to
// the memory-bandwidth bound of its data layout, measured in the same run.
//
// Systems: the run files of Fig. 4.11 (two particles, 44 x 44 x 147 = 284,592 nodes) and of
// the Fig. 4.25 helix (eight particles, 66 x 66 x 228 = 993,168 nodes), built exactly as
// `mresim run` builds them, with every free node displaced at random by up to 0.05 l_e so that
// every spring and cell is strained (the cost of an evaluation does not depend on the state).
//
// Printed per system and thread count (1, then 2; the results are bitwise the same):
//  - the whole evaluation (MessSystem::evaluate: every energy term, the magnetization held);
//  - the elastic kernels alone (springs + volume, ElasticTerms::evaluate);
// each as nodes per second (best of the repeats) and as a fraction of the bandwidth bound.
//
// Bandwidth bound = measured bandwidth / bytes the kernels stream per node. The bandwidth is a
// STREAM-like triad a[i] = b[i] + s c[i] over 3 x 256 MiB, counted as 24 bytes per i, best of
// five, with the same thread count. The bytes per node count every array the two elastic
// kernels sweep once per evaluation (elastic_terms.cpp), with the lattice's own spring and cell
// counts:
//   springs, per node: the positions read (24 B), copied into three component arrays (24 B
//     written) and read back from them (24 B; the neighbours' from cache), the stiffness index
//     of each forward offset (13 B), the gradient read and written (48 B), the stencil's first
//     spring and offset mask for the energy's order (10 B); the tensions stay in a ring of rows
//     per thread that fits the cache (not counted);
//   volume, per node: the positions read into two node planes per thread (24 B) and the
//     gradient read and written (48 B); its cells' coefficients stay in two layer buffers per
//     thread (not counted). Nothing is read per spring or per cell.
// The gathers find a node's springs and cells from the grid (no incidence lists). Neighbouring
// positions are assumed to come from cache (the best case for the layout), so the bound is
// optimistic. The same counting for a layout without index arrays or scratch (positions read
// once, gradient written once, one material byte) gives 49 B per node; that line is printed as
// the bound such a layout could approach.
//
// Also printed: one product of the elastic Hessian with a vector (MessSystem::
// elastic_hessian_product, what Newton's conjugate gradients apply every iteration).
//
//   ./build/mess_throughput_bench                  (both systems)
//   ./build/mess_throughput_bench --repeats 10 --only fig4_11
#include <omp.h>
#include <sys/resource.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include "full_size_systems.hpp"
#include "mresim/mess/protocols/protocol_runner.hpp"
#include "mresim/mess/run_file/mess_spec.hpp"
#include "mresim/mess/terms/elastic_terms.hpp"

namespace {

namespace mess = mresim::mess;
using mresim::bench::best_seconds;
using mresim::bench::seconds_since;
using mresim::bench::SystemFile;

// STREAM-like triad with `threads` threads: best bandwidth of five passes, bytes/s.
double triad_bandwidth(int threads) {
  constexpr std::size_t kCount = std::size_t{1} << 25;  // 256 MiB per array
  std::vector<double> a(kCount);
  std::vector<double> b(kCount);
  std::vector<double> c(kCount);
  const auto n = static_cast<std::int64_t>(kCount);
#pragma omp parallel for schedule(static) num_threads(threads)
  for (std::int64_t i = 0; i < n; ++i) {  // first touch by the threads that use the pages
    a[i] = 0.0;
    b[i] = 1.0;
    c[i] = 2.0;
  }
  double best = 1e300;
  for (int pass = 0; pass < 5; ++pass) {
    const auto start = std::chrono::steady_clock::now();
#pragma omp parallel for schedule(static) num_threads(threads)
    for (std::int64_t i = 0; i < n; ++i) a[i] = b[i] + 0.5 * c[i];
    best = std::min(best, seconds_since(start));
  }
  if (a[kCount / 2] != 2.0) std::abort();  // keeps the loop and checks it ran
  return 24.0 * static_cast<double>(kCount) / best;
}

// Bytes the elastic kernels stream per node (see the header for the counting).
constexpr double kSpringBytesPerNode = 24.0 + 24.0 + 24.0 + 13.0 + 48.0 + 10.0;
constexpr double kVolumeBytesPerNode = 24.0 + 48.0;
constexpr double kElasticBytesPerNode = kSpringBytesPerNode + kVolumeBytesPerNode;
constexpr double kStencilBytesPerNode = 24.0 + 24.0 + 1.0;

struct Measured {
  double whole = 0.0;    // s per evaluation
  double elastic = 0.0;  // s per evaluation
  double hessian = 0.0;  // s per elastic Hessian product
  Eigen::Matrix3Xd gradient;
  std::array<double, 2> values{};  // the whole evaluation's potential and rounding magnitude
};

Measured measure(mess::MessSystem& system, const mess::ElasticTerms& elastic, int threads,
                 int repeats) {
  omp_set_num_threads(threads);
  Measured m;
  m.gradient.resize(3, system.node_count());
  // Warm-up (first touch of the scratch arrays); its values are the fingerprinted ones.
  const mess::Evaluation first = system.evaluate(&m.gradient);
  m.values = {first.potential, first.magnitude};
  m.whole = best_seconds(repeats, [&] { (void)system.evaluate(&m.gradient); });
  Eigen::Matrix3Xd elastic_gradient(3, system.node_count());
  (void)elastic.evaluate(system.lattice(), system.positions(), &elastic_gradient);
  m.elastic = best_seconds(repeats, [&] {
    (void)elastic.evaluate(system.lattice(), system.positions(), &elastic_gradient);
  });
  const Eigen::Matrix3Xd direction = elastic_gradient.normalized();
  Eigen::Matrix3Xd product = system.elastic_hessian_product(direction);
  m.hessian = best_seconds(repeats, [&] { product = system.elastic_hessian_product(direction); });
  return m;
}

void run_system(const SystemFile& file, int repeats, const double bandwidth[3]) {
  const mresim::mess_config::MessSpec spec = mresim::bench::read_system_spec(file);
  const auto build_start = std::chrono::steady_clock::now();
  const mresim::mess_protocol::ProtocolRunner runner(spec);
  mess::MessSystem system = runner.system();
  const double build_seconds = seconds_since(build_start);
  const std::int64_t nodes = system.node_count();
  std::mt19937_64 random(20261202);
  mresim::bench::displace_at_random(system, random);
  (void)system.solve_magnetization();
  const mess::ElasticTerms elastic(system.lattice(), {});

  const double bytes = kElasticBytesPerNode;
  std::printf("\n%s: %lld nodes, %zu springs, %zu cells, %zu particles (built in %.1f s)\n",
              file.name, static_cast<long long>(nodes), system.lattice().springs.size(),
              system.lattice().elements.size(), system.particle_count(), build_seconds);
  std::printf(
      "  bytes the elastic kernels stream per node: %.0f (without index arrays or scratch: %.0f)\n",
      bytes, kStencilBytesPerNode);
  Eigen::Matrix3Xd first_gradient;
  for (const int threads : {1, 2}) {
    const Measured m = measure(system, elastic, threads, repeats);
    const double bound = bandwidth[threads] / bytes;  // nodes/s
    const double stencil_bound = bandwidth[threads] / kStencilBytesPerNode;
    const double whole_rate = static_cast<double>(nodes) / m.whole;
    const double elastic_rate = static_cast<double>(nodes) / m.elastic;
    std::printf(
        "  %d thread%s: whole evaluation %7.2f ms = %6.2f M nodes/s; elastic kernels %7.2f ms = "
        "%6.2f M nodes/s = %3.0f %% of the layout's bound (%.1f M nodes/s); bound without index "
        "arrays %.0f M "
        "nodes/s\n",
        threads, threads == 1 ? " " : "s", 1e3 * m.whole, 1e-6 * whole_rate, 1e3 * m.elastic,
        1e-6 * elastic_rate, 100.0 * elastic_rate / bound, 1e-6 * bound, 1e-6 * stencil_bound);
    std::printf("             elastic Hessian product %7.2f ms = %6.2f M nodes/s\n",
                1e3 * m.hessian, 1e-6 * static_cast<double>(nodes) / m.hessian);
    if (threads == 1) {
      first_gradient = m.gradient;
    } else {
      std::printf("  gradient with 2 threads %s the one with 1 thread\n",
                  first_gradient == m.gradient ? "bitwise equals" : "DIFFERS FROM");
      // The same bits from another build: the same fingerprint.
      const std::uint64_t bits = mresim::bench::fingerprint(
          m.gradient.data(), m.gradient.size(), mresim::bench::fingerprint(m.values.data(), 2));
      std::printf(
          "  fingerprint of the whole evaluation's gradient, potential and magnitude: "
          "%016llx\n",
          static_cast<unsigned long long>(bits));
    }
  }
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
  const auto options = mresim::bench::parse_bench_options(argc, argv, 5);
  if (!options) return 2;
  mresim::bench::print_load_average();
  double bandwidth[3] = {0.0, 0.0, 0.0};
  for (const int threads : {1, 2}) {
    bandwidth[threads] = triad_bandwidth(threads);
    std::printf("triad bandwidth, %d thread%s: %.1f GB/s\n", threads, threads == 1 ? "" : "s",
                1e-9 * bandwidth[threads]);
  }
  mresim::bench::for_each_system(
      *options, [&](const SystemFile& file) { run_system(file, options->repeats, bandwidth); });
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  std::printf("\npeak resident memory of the process: %.1f MiB\n",
              static_cast<double>(usage.ru_maxrss) / 1024.0);
  return 0;
}
