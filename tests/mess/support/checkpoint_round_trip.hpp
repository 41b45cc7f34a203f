#pragma once

// A run interrupted after some steps and resumed as a new process would: the steps on one
// runner, a checkpoint written, and the state read back into another runner.

#include <cstddef>
#include <filesystem>
#include <string>

#include "mresim/mess/outputs/checkpoint.hpp"
#include "mresim/mess/protocols/protocol_runner.hpp"

namespace mresim::mess_protocol::testing {

// Runs the first `steps` steps of `runner`'s run file (`toml`) on a runner of its own, writes the
// checkpoint to `checkpoint` and returns the state read from it into `runner`.
inline ProtocolState resumed_after(const std::string& toml, std::size_t steps,
                                   const std::filesystem::path& checkpoint,
                                   ProtocolRunner& runner) {
  {
    ProtocolRunner first(runner.spec());
    ProtocolState partial = first.initial_state();
    for (std::size_t i = 0; i < steps; ++i) first.run_next_step(partial);
    write_checkpoint(checkpoint, partial, first, toml, "test.toml");
  }
  return read_checkpoint(checkpoint, runner, toml);
}

}  // namespace mresim::mess_protocol::testing
