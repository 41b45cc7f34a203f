#include "mresim/io/csv_reader.hpp"

#include <fmt/format.h>

#include <fstream>
#include <iterator>
#include <stdexcept>

namespace mresim::io {

CsvTable read_csv(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw std::runtime_error(fmt::format("cannot read '{}'", file.string()));
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());

  std::vector<std::vector<std::string>> records;
  std::vector<std::string> record;
  std::string cell;
  bool quoted = false;
  bool any = false;  // the current record has content (a blank line is no record)
  const auto end_record = [&] {
    if (any) {
      record.push_back(std::move(cell));
      records.push_back(std::move(record));
    }
    record.clear();
    cell.clear();
    any = false;
  };
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (quoted) {
      if (c == '"' && i + 1 < text.size() && text[i + 1] == '"') {
        cell.push_back('"');
        ++i;
      } else if (c == '"') {
        quoted = false;
      } else {
        cell.push_back(c);
      }
      continue;
    }
    switch (c) {
      case '"':
        quoted = any = true;
        break;
      case ',':
        record.push_back(std::move(cell));
        cell.clear();
        any = true;
        break;
      case '\r':
        break;
      case '\n':
        end_record();
        break;
      default:
        cell.push_back(c);
        any = true;
    }
  }
  if (quoted) {
    throw std::runtime_error(
        fmt::format("'{}': a quoted cell is not closed at the end of the file", file.string()));
  }
  end_record();
  if (records.empty()) throw std::runtime_error(fmt::format("'{}' has no header", file.string()));

  CsvTable table;
  table.columns = std::move(records.front());
  for (std::size_t r = 1; r < records.size(); ++r) {
    if (records[r].size() != table.columns.size()) {
      throw std::runtime_error(fmt::format("'{}': row {} has {} cells, the header {}",
                                           file.string(), r, records[r].size(),
                                           table.columns.size()));
    }
    table.rows.push_back(std::move(records[r]));
  }
  return table;
}

}  // namespace mresim::io
