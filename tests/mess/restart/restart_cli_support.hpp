#pragma once

// What the `mresim extend`, `mresim rerun` and `mresim resume` tests share: small 3D run files,
// running the command line in a temporary directory, finding a running process's checkpoint,
// and comparing the step datasets of two runs.

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include "../../support/hdf5_read.hpp"
#include "../../support/temp_dir.hpp"
#include "../support/small_runs.hpp"

namespace mresim::mess_protocol::testing {

// mess_hysteresis of the small two-particle model, fields 0 .. max in `steps` increments
// (`sequence` "up" or "loop"), no checkpoints.
inline std::string small_field_run(double max_tesla, int steps, const std::string& sequence,
                                   bool node_positions = false) {
  return std::string("[run]\ntype = \"mess_hysteresis\"\n") + kSmallModel +
         "\n[field]\nmax = " + std::to_string(max_tesla) + "\nsteps = " + std::to_string(steps) +
         "\nsequence = \"" + sequence + "\"\n\n[output]\ncheckpoint_every = 0\nnode_positions = " +
         (node_positions ? "true" : "false") + "\n";
}

// The options that keep a run of the command line quiet and single-threaded.
inline const char* const kQuiet = " --no-plot -j 1";

// `mresim ARGS` in `dir`: the exit status; stderr in dir/.stderr.
inline int mresim_in(const std::filesystem::path& dir, const std::string& args) {
  const std::string command = "cd '" + dir.string() + "' && '" + MRESIM_CLI_PATH + "' " + args +
                              " >/dev/null 2>'" + (dir / ".stderr").string() + "' </dev/null";
  const int raw = std::system(command.c_str());
  return WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
}

inline std::string last_stderr(const std::filesystem::path& dir) {
  return mresim::testing::read_text(dir / ".stderr");
}

// The checkpoint in the staging directory (OUT.partial-...) of a running process writing to
// `dir`/`out`, once it exists; empty before.
inline std::filesystem::path staged_checkpoint(const std::filesystem::path& dir,
                                               const std::string& out) {
  for (const auto& e : std::filesystem::directory_iterator(dir)) {
    const std::string name = e.path().filename().string();
    if (name.rfind(out + ".partial-", 0) == 0 &&
        std::filesystem::exists(e.path() / "checkpoint.h5")) {
      return e.path() / "checkpoint.h5";
    }
  }
  return {};
}

// The step datasets (everything a step computes; not the wall time) of two runs, bit for bit.
inline void expect_identical_steps(const std::filesystem::path& a_dir,
                                   const std::filesystem::path& b_dir) {
  const mresim::testing::Hdf5Reader a(a_dir / "results.h5");
  const mresim::testing::Hdf5Reader b(b_dir / "results.h5");
  for (const char* path :
       {"/steps/field", "/steps/load_value", "/steps/energies/total", "/steps/energies/springs",
        "/steps/energies/volume", "/steps/energies/dipole", "/steps/energies/zeeman",
        "/steps/centres", "/steps/magnetization", "/steps/system_volume", "/steps/box_strain",
        "/steps/measured_strain", "/steps/solver/max_force"}) {
    EXPECT_EQ(a.doubles(path), b.doubles(path)) << path;
  }
  for (const char* path : {"/steps/index", "/steps/field_index", "/steps/load_index",
                           "/steps/solver/iterations", "/steps/solver/evaluations"}) {
    EXPECT_EQ(a.ints(path), b.ints(path)) << path;
  }
}

}  // namespace mresim::mess_protocol::testing
