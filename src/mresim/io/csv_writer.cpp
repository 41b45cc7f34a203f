#include "mresim/io/csv_writer.hpp"

#include <fmt/format.h>

#include <cstdio>
#include <stdexcept>

namespace mresim::io {

namespace {

std::string csv_text(const std::string& text) {
  const bool needs_quotes = text.find_first_of(",\"\r\n") != std::string::npos ||
                            (!text.empty() && (text.front() == ' ' || text.back() == ' '));
  if (!needs_quotes) return text;
  std::string quoted = "\"";
  for (const char c : text) {
    if (c == '"') quoted += '"';  // RFC 4180: a quote inside a quoted field is doubled
    quoted += c;
  }
  return quoted + "\"";
}

}  // namespace

std::string format_csv_number(double x) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.10g", x);
  return buffer;
}

CsvWriter::CsvWriter(const std::filesystem::path& file, std::vector<std::string> columns)
    : path_(file), columns_(std::move(columns)), out_(file, std::ios::out | std::ios::trunc) {
  if (!out_) throw std::runtime_error(fmt::format("cannot create CSV file '{}'", path_.string()));
  if (columns_.empty()) {
    throw std::invalid_argument(
        fmt::format("CSV file '{}' needs at least one column", path_.string()));
  }
  for (std::size_t i = 0; i < columns_.size(); ++i)
    out_ << (i > 0 ? "," : "") << csv_text(columns_[i]);
  end_line();
}

void CsvWriter::check_size(std::size_t count) const {
  if (count != columns_.size()) {
    throw std::invalid_argument(fmt::format("CSV file '{}': row has {} values, expected {} columns",
                                            path_.string(), count, columns_.size()));
  }
}

void CsvWriter::end_line() {
  out_ << '\n';
  if (!out_) throw std::runtime_error(fmt::format("cannot write CSV file '{}'", path_.string()));
}

void CsvWriter::row(const std::vector<double>& values) {
  check_size(values.size());
  for (std::size_t i = 0; i < values.size(); ++i)
    out_ << (i > 0 ? "," : "") << format_csv_number(values[i]);
  end_line();
  ++rows_;
}

void CsvWriter::row_cells(const std::vector<Cell>& cells) {
  check_size(cells.size());
  for (std::size_t i = 0; i < cells.size(); ++i) {
    if (i > 0) out_ << ',';
    if (const auto* x = std::get_if<double>(&cells[i])) {
      out_ << format_csv_number(*x);
    } else {
      out_ << csv_text(std::get<std::string>(cells[i]));
    }
  }
  end_line();
  ++rows_;
}

void CsvWriter::close() {
  if (!out_.is_open()) return;
  out_.close();
  if (out_.fail())
    throw std::runtime_error(fmt::format("cannot write CSV file '{}'", path_.string()));
}

}  // namespace mresim::io
