// Fuzz target for the run-file reader: any byte string is parsed as a TOML run file, validated
// by the run type it names and described as `mresim info` would. Bad input must end in a
// config::ConfigError (the one-line message `mresim` prints with exit status 2); a crash, a
// sanitizer report, a hang, an uncaught exception of another type or a message of more than one
// line is a finding.
//
// Build and run: see docs/fuzzing.md (clang with -DMRESIM_BUILD_FUZZ=ON; libFuzzer).

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>

#include "mresim/app/info_report.hpp"
#include "mresim/app/run_type.hpp"
#include "mresim/config/config_error.hpp"
#include "mresim/config/table_reader.hpp"

namespace {

[[noreturn]] void finding(const char* kind, const std::string& what) {
  std::fprintf(stderr, "run_file_fuzzer: %s: %s\n", kind, what.c_str());
  std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const auto root = mresim::config::TableReader::parse_string(text, "fuzz.toml");
    const auto plan = mresim::app::make_plan(root);
    mresim::app::InfoReport report;
    plan->describe(report);
    (void)report.to_text();
    (void)report.to_json().dump();
  } catch (const mresim::config::ConfigError& e) {
    const std::string message = e.what();
    if (message.empty() || message.find('\n') != std::string::npos) {
      finding("error message is not one line", message);
    }
  } catch (const std::exception& e) {
    finding("exception other than ConfigError", e.what());
  }
  return 0;
}
