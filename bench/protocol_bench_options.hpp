#pragma once

// What the benches that run a protocol twice share (strain_start_bench, node_scaling_bench): a
// run of every step of a run file with what it cost, and their command line: --order N (the
// discretization order), --steps K (load or field steps) and --repeats R (runs of each variant).

#include <fmt/format.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "mresim/config/table_reader.hpp"
#include "mresim/mess/protocols/protocol_runner.hpp"
#include "mresim/mess/run_file/mess_spec.hpp"

namespace mresim::bench {

// CPU seconds of this process (all threads).
inline double cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

// One run of a run file's steps: every step's record, and the CPU time, iterations and
// evaluations of the steps counted.
struct ProtocolRun {
  std::vector<mess_protocol::StepRecord> records;
  double cpu = std::numeric_limits<double>::infinity();  // s
  std::int64_t iterations = 0;
  std::int64_t evaluations = 0;
  std::int64_t nodes = 0;
};

// Runs every step of the example run file `example` (relative to the source tree) with the
// overrides (--set's KEY=VALUE); counts the steps for which counted(record) is true. Exits with
// status 1 if a step does not converge (`label` names the run in the message).
template <class Counted>
ProtocolRun run_protocol(const std::string& example, const std::vector<std::string>& overrides,
                         const std::string& label, Counted&& counted) {
  const mess_config::MessSpec spec = mess_config::read_mess_run_file(
      config::TableReader::parse_file(std::string(MRESIM_SOURCE_DIR) + "/" + example, overrides));
  mess_protocol::ProtocolRunner runner(spec);
  mess_protocol::ProtocolState state = runner.initial_state();
  ProtocolRun r;
  r.nodes = runner.system().node_count();
  double cpu = 0.0;
  while (state.next_step < runner.steps().size()) {
    const double cpu0 = cpu_seconds();
    const mess_protocol::StepRecord& record = runner.run_next_step(state);
    if (counted(record)) {
      cpu += cpu_seconds() - cpu0;
      r.iterations += record.iterations;
      r.evaluations += record.evaluations;
    }
    if (!record.converged) {
      std::fprintf(stderr, "%s: step %zu did not converge (%s)\n", label.c_str(), record.step.index,
                   record.status.c_str());
      std::exit(1);
    }
  }
  r.cpu = cpu;
  r.records = state.records;
  return r;
}

struct ProtocolBenchOptions {
  int order = 0;
  int steps = 0;
  int repeats = 1;
};

// The options, each at least 1, with these defaults; std::nullopt (after a message on stderr)
// for an unknown option or one without its value.
inline std::optional<ProtocolBenchOptions> parse_protocol_bench_options(int argc, char** argv,
                                                                        int order, int steps) {
  ProtocolBenchOptions options{order, steps, 1};
  for (int k = 1; k < argc; k += 2) {
    const std::string key = argv[k];
    int* value = key == "--order"     ? &options.order
                 : key == "--steps"   ? &options.steps
                 : key == "--repeats" ? &options.repeats
                                      : nullptr;
    if (value == nullptr || k + 1 >= argc) {
      std::fprintf(stderr, "unknown option %s (--order N, --steps K, --repeats R)\n", argv[k]);
      return std::nullopt;
    }
    *value = std::max(1, std::atoi(argv[k + 1]));
  }
  return options;
}

}  // namespace mresim::bench
