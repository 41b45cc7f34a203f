#pragma once

// The peak resident memory of this process, for the per-run memory report of the 3D runs
// (docs/outputs-3d.md: /@peak_resident_memory_bytes): the figure that says whether a system of
// a given size fits a machine, measured rather than estimated.

#include <cstdint>

namespace mresim::app {

// Bytes (getrusage's ru_maxrss, which Linux reports in KiB); 0 if the system does not say.
// The whole process: a run from Python counts the interpreter too, a resumed run only what
// this process used.
std::int64_t peak_resident_memory_bytes();

}  // namespace mresim::app
