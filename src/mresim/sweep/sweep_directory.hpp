#pragma once

// The layout of a sweep directory (`mresim sweep FILE --out DIR`, docs/sweeps.md):
//
//   DIR/sweep.json            the points and their parameters (written before any point runs)
//   DIR/base.toml             the run file without [sweep]; each point runs it with --set
//   DIR/point-0003/           the run directory of point 3 (an ordinary `mresim run` output)
//   DIR/logs/point-0003.log   its stdout and stderr
//   DIR/logs/point-0003.status  its exit status, one line
//   DIR/collected*.csv, DIR/collected.h5   `mresim collect DIR`

#include <cstddef>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "mresim/sweep/sweep_spec.hpp"

namespace mresim::sweep {

inline constexpr const char* kRecordFile = "sweep.json";
inline constexpr const char* kBaseFile = "base.toml";
inline constexpr const char* kLogsDir = "logs";

// "point-0003" (four digits; more when the sweep has more than 10,000 points).
[[nodiscard]] std::string point_name(std::size_t index, std::size_t count);

// What sweep.json holds: the run file's name, the swept keys and, per point, its directory, its
// `--set` arguments and its values (JSON numbers, strings and booleans where the TOML value is
// one, else the TOML text).
[[nodiscard]] nlohmann::json sweep_record(const SweepSpec& spec, const std::string& run_file);

// Whether `dir` is a sweep directory (holds sweep.json).
[[nodiscard]] bool is_sweep_directory(const std::filesystem::path& dir);

// Writes sweep.json and base.toml into `dir` (created if missing). A directory that already
// holds a sweep must hold this very sweep (same sweep.json), so that finished points can be
// skipped; another sweep, or an existing directory with other files and no sweep.json, is
// refused (io::OutputDirectoryError naming the directory). Safe when several processes of
// one sweep (a Slurm array) do it at once: each file is written whole and renamed into place.
void prepare_sweep_directory(const std::filesystem::path& dir, const SweepSpec& spec,
                             const std::string& run_file);

// The state of one point as its directory and log files tell it.
enum class PointStatus { finished, invalid_results, failed, pending };
[[nodiscard]] const char* status_name(PointStatus status);

struct PointState {
  PointStatus status = PointStatus::pending;
  int exit_status = -1;  // of the last attempt; -1 when unknown (not run, or run elsewhere)
  std::string message;   // failed: the last error line of its log
};
[[nodiscard]] PointState point_state(const std::filesystem::path& dir, std::size_t index,
                                     std::size_t count);

// The log and status files of a point.
[[nodiscard]] std::filesystem::path log_file(const std::filesystem::path& dir, std::size_t index,
                                             std::size_t count);
[[nodiscard]] std::filesystem::path status_file(const std::filesystem::path& dir, std::size_t index,
                                                std::size_t count);
// Records a point's exit status (written whole, then renamed).
void write_point_status(const std::filesystem::path& dir, std::size_t index, std::size_t count,
                        int exit_status);

// Reads DIR/sweep.json; throws io::OutputDirectoryError when it is missing or malformed.
[[nodiscard]] nlohmann::json read_sweep_record(const std::filesystem::path& dir);

}  // namespace mresim::sweep
