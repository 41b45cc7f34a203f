#pragma once

// `mresim run` of a run file's text in a temporary directory, and the CSV files it writes, for
// the 3D output tests.

#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "../../support/temp_dir.hpp"

namespace mresim::mess_protocol::testing {

struct CliRun {
  int status = -1;
  std::string err;
};

// `mresim run run.toml --out out --no-plot -j 1` in `dir`: exit status and stderr.
inline CliRun run_in(const mresim::testing::TempDir& dir, const std::string& toml) {
  std::ofstream(dir / "run.toml") << toml;
  const std::string command = "cd '" + dir.path().string() + "' && '" + MRESIM_CLI_PATH +
                              "' run run.toml --out out --no-plot -j 1 >/dev/null 2>err.txt";
  const int raw = std::system(command.c_str());
  CliRun r;
  if (WIFEXITED(raw)) r.status = WEXITSTATUS(raw);
  r.err = mresim::testing::read_text(dir / "err.txt");
  return r;
}

// A CSV file as rows of cells (the header first).
inline std::vector<std::vector<std::string>> csv_rows(const std::filesystem::path& file) {
  std::vector<std::vector<std::string>> rows;
  std::istringstream in(mresim::testing::read_text(file));
  for (std::string line; std::getline(in, line);) {
    std::vector<std::string> cells;
    std::istringstream l(line);
    for (std::string cell; std::getline(l, cell, ',');) cells.push_back(cell);
    rows.push_back(cells);
  }
  return rows;
}

// The column of `name` in a header row.
inline std::size_t column_of(const std::vector<std::string>& header, const std::string& name) {
  for (std::size_t i = 0; i < header.size(); ++i) {
    if (header[i] == name) return i;
  }
  throw std::runtime_error("no column " + name);
}

// `text` with the first `from` replaced by `to`.
inline std::string with(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  if (at == std::string::npos) throw std::logic_error("with: '" + from + "' not found");
  return text.replace(at, from.size(), to);
}

}  // namespace mresim::mess_protocol::testing
