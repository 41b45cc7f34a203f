// The minimisers' multilevel preconditioner at full size (solvers/preconditioner.hpp,
// solvers/multilevel_correction.hpp): what a relaxation with `method = "minimiser"` pays for it.
// A relaxation builds it once at its starting state and applies it about twice per L-BFGS
// iteration (once in the two-loop recursion, once for H0's scale).
//
// Problem: the Fig. 4.11 pair (284,592 nodes) and the Fig. 4.25 helix (993,168 nodes) from their
// run files, every node displaced at random by up to 0.05 l_e (fixed seed) as the state the
// preconditioner is linearised at, the free coordinates those left by holding all six faces (as
// the hysteresis runs of Chapter 4 do).
// Printed for each node scaling (solver.node_scaling: the nodes' 3 x 3 blocks, the default, and
// the diagonal) with 1 and 2 threads (best of the repeats): the build (the diagonal, the particles'
// rigid blocks and the multilevel correction's assembly and coarse factor), one application of
// the whole preconditioner and of the multilevel correction alone, and the application as
// nodes per second. Also printed: whether the results with 2 threads are bitwise those with 1,
// and a 64-bit fingerprint of the applied vector, so that two builds of this bench can be
// compared for bitwise equal results; and the load average (the machine is shared).
//
//   ./build/preconditioner_bench [--repeats 10] [--only fig4_11|fig4_25_helix]
#include <omp.h>

#include <cstdio>
#include <memory>
#include <random>

#include "full_size_systems.hpp"
#include "mresim/mess/protocols/protocol_runner.hpp"
#include "mresim/mess/solvers/preconditioner.hpp"

namespace {

namespace mess = mresim::mess;
using mresim::bench::best_seconds;
using mresim::bench::SystemFile;

struct Measured {
  double build = 0.0;       // s
  double apply = 0.0;       // s per application of P
  double correction = 0.0;  // s per application of the multilevel correction alone
  Eigen::VectorXd applied;  // P v
};

Measured measure(const mess::MessSystem& system, const mess::DofMap& map, double force_scale,
                 const Eigen::VectorXd& v, int threads, int repeats, mess::NodeScaling scaling) {
  omp_set_num_threads(threads);
  Measured m;
  std::unique_ptr<mess::RigidParticlePreconditioner> p;
  // The build allocates and first-touches everything it keeps: best of a few, one held at a
  // time as in a run.
  m.build = best_seconds(std::clamp(repeats / 4, 1, 3), [&] {
    p.reset();
    p = std::make_unique<mess::RigidParticlePreconditioner>(system, map, force_scale, true,
                                                            &system.positions(), nullptr, scaling);
  });
  if (p->multilevel() == nullptr) {
    std::fprintf(stderr, "the multilevel correction was left out (nothing held)\n");
    std::exit(1);
  }
  m.applied = p->apply(map, v);  // warm-up
  m.apply = best_seconds(repeats, [&] { m.applied = p->apply(map, v); });
  Eigen::VectorXd w = Eigen::VectorXd::Zero(v.size());
  m.correction = best_seconds(repeats, [&] {
    w.setZero();
    p->multilevel()->add_to(map, v, w);
  });
  return m;
}

void run_system(const SystemFile& file, int repeats) {
  const mresim::mess_protocol::ProtocolRunner runner(mresim::bench::read_system_spec(file));
  mess::MessSystem system = runner.system();
  const std::int64_t nodes = system.node_count();
  std::mt19937_64 random(20261205);
  mresim::bench::displace_at_random(system, random);
  const Eigen::Matrix3Xd& x = system.positions();
  mresim::bench::hold_all_faces(system);  // as the hysteresis runs of Chapter 4 hold them
  system.apply_constraints();
  const double l_e = system.length_scale();
  const mess::DofMap map(system.constraints(), system.positions(), l_e);
  const double force_scale = 1e-9;  // any fixed scale: P scales with l_e / force_scale
  std::normal_distribution<double> normal;
  Eigen::VectorXd v(map.size());
  for (Eigen::Index k = 0; k < v.size(); ++k) v[k] = normal(random);

  std::printf("\n%s: %lld nodes, %lld free coordinates\n", file.name, static_cast<long long>(nodes),
              static_cast<long long>(map.size()));
  for (const mess::NodeScaling scaling : {mess::NodeScaling::blocks, mess::NodeScaling::diagonal}) {
    std::printf("  node scaling \"%s\"\n",
                scaling == mess::NodeScaling::blocks ? "blocks" : "diagonal");
    Eigen::VectorXd first;
    for (const int threads : {1, 2}) {
      const Measured m = measure(system, map, force_scale, v, threads, repeats, scaling);
      std::printf(
          "  %d thread%s: build %7.3f s; apply P %7.2f ms = %6.1f M nodes/s, of which the "
          "multilevel correction %7.2f ms; fingerprint of P v %016llx\n",
          threads, threads == 1 ? " " : "s", m.build, 1e3 * m.apply,
          1e-6 * static_cast<double>(nodes) / m.apply, 1e3 * m.correction,
          static_cast<unsigned long long>(
              mresim::bench::fingerprint(m.applied.data(), m.applied.size())));
      if (threads == 1) {
        first = m.applied;
      } else {
        std::printf("  P v with 2 threads %s the one with 1 thread\n",
                    first == m.applied ? "bitwise equals" : "DIFFERS FROM");
      }
    }
  }
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
  const auto options = mresim::bench::parse_bench_options(argc, argv, 10);
  if (!options) return 2;
  mresim::bench::print_load_average();
  mresim::bench::for_each_system(
      *options, [&](const SystemFile& file) { run_system(file, options->repeats); });
  return 0;
}
