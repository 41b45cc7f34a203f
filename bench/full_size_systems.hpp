#pragma once

// What the full-size benches share (mess_throughput_bench, preconditioner_bench): the two
// full-size systems they build from the example run files, their command line (--repeats N,
// --only NAME), timing by the best of repeated calls, and fingerprints of results' bits.

#include <algorithm>
#include <bit>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <random>
#include <string>
#include <utility>

#include "mresim/config/table_reader.hpp"
#include "mresim/mess/run_file/mess_spec.hpp"
#include "mresim/mess/system/system_energy.hpp"

namespace mresim::bench {

struct SystemFile {
  const char* name;
  const char* path;  // relative to the source tree
};

inline constexpr SystemFile kFullSizeSystems[] = {
    {"fig4_11", "examples/chapter4/fig4_11_pair_large_box_S6_5um.toml"},
    {"fig4_25_helix", "examples/chapter4/fig4_25_helix_R3_5um.toml"},
};

// FNV-1a over the bits of `count` doubles, continuing from `hash`: equal fingerprints, bitwise
// equal results (up to collisions), so two builds of a bench can be compared bit for bit.
inline std::uint64_t fingerprint(const double* values, std::int64_t count,
                                 std::uint64_t hash = 0xcbf29ce484222325ULL) {
  for (std::int64_t k = 0; k < count; ++k) {
    const auto bits = std::bit_cast<std::uint64_t>(values[k]);
    for (int byte = 0; byte < 8; ++byte) {
      hash ^= (bits >> (8 * byte)) & 0xffU;
      hash *= 0x100000001b3ULL;
    }
  }
  return hash;
}

// The run file of `file` read from the source tree.
inline mess_config::MessSpec read_system_spec(const SystemFile& file) {
  const std::string path = std::string(MRESIM_SOURCE_DIR) + "/" + file.path;
  return mess_config::read_mess_run_file(config::TableReader::parse_file(path));
}

// Strains every spring and cell: each node displaced at random by up to 0.05 l_e along each
// axis (uniform; with a generator of fixed seed every run measures the same state).
inline void displace_at_random(mess::MessSystem& system, std::mt19937_64& random) {
  std::uniform_real_distribution<double> jitter(-0.05, 0.05);
  Eigen::Matrix3Xd x = system.positions();
  for (Eigen::Index n = 0; n < x.cols(); ++n) {
    for (int a = 0; a < 3; ++a) x(a, n) += jitter(random) * system.length_scale();
  }
  system.set_positions(x);
}

// All six faces of the lattice held where the nodes are now, as the hysteresis runs of Chapter 4
// hold them.
inline void hold_all_faces(mess::MessSystem& system) {
  const Eigen::Matrix3Xd x = system.positions();
  mess::BoundaryConstraints held = mess::BoundaryConstraints::none(system.node_count());
  for (const auto face : {lattice::Face::left, lattice::Face::right, lattice::Face::front,
                          lattice::Face::back, lattice::Face::bottom, lattice::Face::top}) {
    held.fix_face(system.lattice().shape, face, x);
  }
  system.set_constraints(std::move(held));
}

inline double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// Best time of `repeats` calls of f(), in seconds.
template <class F>
double best_seconds(int repeats, F&& f) {
  double best = 1e300;
  for (int k = 0; k < repeats; ++k) {
    const auto start = std::chrono::steady_clock::now();
    f();
    best = std::min(best, seconds_since(start));
  }
  return best;
}

struct BenchOptions {
  int repeats;
  std::string only;  // a system's name, or empty: both
};

// --repeats N and --only NAME; nothing (after a message on stderr) for anything else.
inline std::optional<BenchOptions> parse_bench_options(int argc, char** argv, int repeats) {
  BenchOptions options{repeats, {}};
  for (int k = 1; k + 1 < argc; k += 2) {
    const std::string key = argv[k];
    if (key == "--repeats") {
      options.repeats = std::max(1, std::atoi(argv[k + 1]));
    } else if (key == "--only") {
      options.only = argv[k + 1];
    } else {
      std::fprintf(stderr, "unknown option %s (--repeats N, --only fig4_11|fig4_25_helix)\n",
                   argv[k]);
      return std::nullopt;
    }
  }
  return options;
}

// The load average at the start (the machine is shared).
inline void print_load_average() {
  double load[3] = {0, 0, 0};
  if (getloadavg(load, 3) > 0) std::printf("load average at start: %.2f\n", load[0]);
}

// run(file) for the systems asked for.
template <class Run>
void for_each_system(const BenchOptions& options, Run&& run) {
  for (const SystemFile& file : kFullSizeSystems) {
    if (options.only.empty() || options.only == file.name) run(file);
  }
}

}  // namespace mresim::bench
