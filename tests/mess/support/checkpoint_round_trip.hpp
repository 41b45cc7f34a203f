#pragma once

// A run interrupted after some steps and resumed as a new process would: the steps on one
// runner, a checkpoint written, and the state read back into another runner.

#include <gtest/gtest.h>

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

// The records of two runs' steps are the same, bit for bit, and so are their last states and
// zero-load references at every field.
inline void expect_same_states(const ProtocolState& a, const ProtocolState& b) {
  ASSERT_EQ(a.records.size(), b.records.size());
  for (std::size_t i = 0; i < a.records.size(); ++i) {
    EXPECT_EQ(a.records[i].energies.total(), b.records[i].energies.total()) << "step " << i;
    EXPECT_EQ(a.records[i].centres, b.records[i].centres) << "step " << i;
    EXPECT_EQ(a.records[i].magnetization, b.records[i].magnetization) << "step " << i;
    EXPECT_EQ(a.records[i].measured_strain, b.records[i].measured_strain) << "step " << i;
    EXPECT_EQ(a.records[i].iterations, b.records[i].iterations) << "step " << i;
  }
  ASSERT_EQ(a.slots.size(), b.slots.size());
  for (std::size_t f = 0; f < a.slots.size(); ++f) {
    EXPECT_EQ(a.slots[f].positions.load(), b.slots[f].positions.load()) << "field " << f;
    EXPECT_EQ(a.references[f].load(), b.references[f].load()) << "field " << f;
  }
}

}  // namespace mresim::mess_protocol::testing
