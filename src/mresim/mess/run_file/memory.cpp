// The memory a 3D run needs, and what the process may use: a run that cannot fit is refused
// with a message instead of dying of std::bad_alloc halfway.

#include <fmt/format.h>

#include <cerrno>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>

#include "mresim/mess/run_file/mess_spec.hpp"

namespace mresim::mess_config {

namespace {

// "123" -> 123; anything else (empty, signs, suffixes, overflow) -> std::nullopt.
std::optional<std::int64_t> parse_bytes(const std::string& text) {
  if (text.empty() || text.find_first_not_of("0123456789") != std::string::npos) {
    return std::nullopt;
  }
  errno = 0;
  char* end = nullptr;
  const unsigned long long v = std::strtoull(text.c_str(), &end, 10);
  if (errno != 0 || v > static_cast<unsigned long long>(std::numeric_limits<std::int64_t>::max())) {
    return std::nullopt;
  }
  return static_cast<std::int64_t>(v);
}

// MemAvailable of /proc/meminfo in bytes.
std::optional<std::int64_t> mem_available() {
  std::ifstream in("/proc/meminfo");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("MemAvailable:", 0) != 0) continue;
    std::istringstream fields(line.substr(13));
    long long kib = 0;
    if (fields >> kib && kib >= 0) return static_cast<std::int64_t>(kib) * 1024;
  }
  return std::nullopt;
}

// The cgroup v2 limit ("max" = none).
std::optional<std::int64_t> cgroup_limit() {
  std::ifstream in("/sys/fs/cgroup/memory.max");
  std::string text;
  if (!(in >> text)) return std::nullopt;
  return parse_bytes(text);
}

std::string mib(std::int64_t bytes) {
  return fmt::format("{:.1f} MiB", static_cast<double>(bytes) / static_cast<double>(1 << 20));
}

}  // namespace

std::int64_t bytes_per_node(const MessSpec& spec) {
  // L-BFGS with or without the multilevel preconditioner: one figure (kBytesPerNode).
  return spec.solver.method == SolverMethod::newton ? kNewtonBytesPerNode : kBytesPerNode;
}

std::int64_t scratch_bytes_per_node(const MessSpec& spec) {
  if (spec.load_step_count() <= 1) return 0;
  const auto fields = static_cast<std::int64_t>(spec.field.values.size());
  if (!spec.keeps_earlier_load_results()) return kPerFieldScratchBytesPerNode * fields;
  return (kPerFieldScratchBytesPerNode + kEarlierLoadScratchBytesPerNode) * fields +
         kSecantScratchBytesPerNode;
}

std::int64_t estimated_memory_bytes(const MessSpec& spec) {
  const auto nodes = static_cast<double>(spec.geometry.node_count());
  const auto dim = 3.0 * static_cast<double>(spec.geometry.particle_count());
  const double bytes = static_cast<double>(kFixedBytes) +
                       static_cast<double>(bytes_per_node(spec)) * nodes + 4.0 * 8.0 * dim * dim;
  const auto top = static_cast<double>(std::numeric_limits<std::int64_t>::max());
  return bytes >= top ? std::numeric_limits<std::int64_t>::max() : static_cast<std::int64_t>(bytes);
}

AvailableMemory available_memory() {
  if (const char* limit = std::getenv("MRESIM_MEMORY_LIMIT")) {
    const auto bytes = parse_bytes(limit);
    if (!bytes || *bytes == 0) {
      throw config::ConfigError(fmt::format(
          "MRESIM_MEMORY_LIMIT = \"{}\": must be a positive integer (bytes), the memory a 3D run "
          "may use; unset it to use MemAvailable and the cgroup limit",
          limit));
    }
    return {bytes, "MRESIM_MEMORY_LIMIT"};
  }
  AvailableMemory out;
  if (const auto a = mem_available()) out = {a, "MemAvailable in /proc/meminfo"};
  if (const auto c = cgroup_limit(); c && (!out.bytes || *c < *out.bytes)) {
    out = {c, "the cgroup limit /sys/fs/cgroup/memory.max"};
  }
  return out;
}

void check_memory(const MessSpec& spec, const AvailableMemory& available) {
  const std::int64_t need = estimated_memory_bytes(spec);
  if (!available.bytes || need <= *available.bytes) return;
  const MessGeometry& g = spec.geometry;
  const bool regular = std::holds_alternative<lattice::RegularPlacement>(spec.lattice.placement);
  throw config::ConfigError(fmt::format(
      "the lattice of {} x {} x {} = {} nodes ({} particles) needs an estimated {} ({} + {} "
      "bytes per node), more than the {} available to this process ({}); make the box smaller "
      "({}) or lower model.discretization_order = {}; MRESIM_MEMORY_LIMIT (bytes) overrides "
      "the available figure",
      g.shape.nx(), g.shape.ny(), g.shape.nz(), g.node_count(), g.particle_count(), mib(need),
      mib(kFixedBytes), bytes_per_node(spec), mib(*available.bytes), available.source,
      regular ? "particles.volume_fraction higher or count_per_axis lower" : "box.size",
      spec.lattice.discretization_order));
}

}  // namespace mresim::mess_config
