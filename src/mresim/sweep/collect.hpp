#pragma once

// `mresim collect DIR` (docs/sweeps.md#collected-tables): the tables of every point of a sweep
// in one table each, with the point's index, status and parameters in front of every row.
//
//   DIR/collected_points.csv   one row per point: point, directory, status, exit_status,
//                              message, then one column per swept key
//   DIR/collected_<name>.csv   for every <name>.csv a finished point wrote (summary, modulus,
//                              ...): point, status, the swept keys, then the point's columns, one
//                              row per row of the point's table; a point without that table
//                              (failed, pending) appears as one row with empty cells
//   DIR/collected.h5           the same tables as groups /points, /<name> of one dataset per
//                              column (numbers as float64, NaN for empty cells; text columns as
//                              strings); root attributes `parameters` (the keys, one a line)
//                              and `sweep` (sweep.json)

#include <cstddef>
#include <filesystem>
#include <vector>

namespace mresim::sweep {

struct CollectResult {
  std::size_t finished = 0;  // including those with invalid results
  std::size_t invalid_results = 0;
  std::size_t failed = 0;
  std::size_t pending = 0;
  std::vector<std::filesystem::path> written;  // the files, in the order written
};

// Throws io::OutputDirectoryError when `dir` is not a sweep directory, std::runtime_error when
// a point's table cannot be read or a file cannot be written (nothing half-written is left:
// each file is written whole and renamed into place).
CollectResult collect(const std::filesystem::path& dir);

}  // namespace mresim::sweep
