#pragma once
// The message of the ConfigError an action throws, for tests of the run-file reader's messages.

#include <gtest/gtest.h>

#include <functional>
#include <string>

#include "mresim/config/config_error.hpp"

namespace mresim::testing {

// The ConfigError's message; fails the calling test if `action` throws nothing.
inline std::string config_error_of(const std::function<void()>& action) {
  try {
    action();
  } catch (const config::ConfigError& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected a ConfigError";
  return {};
}

}  // namespace mresim::testing
