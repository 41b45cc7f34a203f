#pragma once

#include <cstddef>
#include <filesystem>
#include <fstream>
#include <string>
#include <variant>
#include <vector>

namespace mresim::io {

// A CSV table (RFC 4180) with a fixed header, for spreadsheets and quick plots (summary.csv).
// Numbers are written with 10 significant digits ("%.10g"): enough to tell neighbouring field
// steps apart, short enough to read. Text cells are quoted only when they need it.
class CsvWriter {
 public:
  using Cell = std::variant<double, std::string>;

  // Creates (truncates) the file and writes the header line.
  CsvWriter(const std::filesystem::path& file, std::vector<std::string> columns);

  // One row of numbers; throws std::invalid_argument if the count differs from the header.
  void row(const std::vector<double>& values);
  // One row mixing text (labels) and numbers. (Not an overload of row(): a braced list of
  // numbers would be ambiguous between the two.)
  void row_cells(const std::vector<Cell>& cells);

  [[nodiscard]] const std::vector<std::string>& columns() const { return columns_; }
  [[nodiscard]] std::size_t rows_written() const { return rows_; }

  // Flushes and closes, throwing if anything failed to reach the disk. Optional: the destructor
  // closes too, but silently.
  void close();

 private:
  void check_size(std::size_t count) const;
  void end_line();

  std::filesystem::path path_;
  std::vector<std::string> columns_;
  std::ofstream out_;
  std::size_t rows_ = 0;
};

// "%.10g" of x ("nan", "inf" and "-inf" for non-finite values).
std::string format_csv_number(double x);

}  // namespace mresim::io
