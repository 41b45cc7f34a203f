#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace mresim::io {

// A CSV table (RFC 4180: quoted cells may hold commas, doubled quotes and line breaks), as the
// CsvWriter writes them: the header's names and the rows' cells as text.
struct CsvTable {
  std::vector<std::string> columns;
  std::vector<std::vector<std::string>> rows;
};

// Reads `file`; throws std::runtime_error naming the file (and the line) when it cannot be
// read, has no header, or a row's cell count differs from the header's.
CsvTable read_csv(const std::filesystem::path& file);

}  // namespace mresim::io
