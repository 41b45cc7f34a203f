#pragma once

// Reading a JSON file (tests/data/...) in a test.

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

namespace mresim::testing {

inline nlohmann::json read_json(const std::filesystem::path& file) {
  std::ifstream in(file);
  return nlohmann::json::parse(in);
}

}  // namespace mresim::testing
