#include "mresim/sweep/collect.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <string>

#include "mresim/io/csv_reader.hpp"
#include "mresim/io/csv_writer.hpp"
#include "mresim/io/hdf5_file.hpp"
#include "mresim/sweep/sweep_directory.hpp"

namespace mresim::sweep {

namespace fs = std::filesystem;

namespace {

// A table of text cells with named columns, as collected before it is written.
struct Table {
  std::vector<std::string> columns;
  std::vector<std::vector<std::string>> rows;
};

struct Point {
  std::size_t index = 0;
  std::string directory;
  PointState state;
  std::vector<std::string> parameters;  // one cell per swept key
};

std::string cell_text(const nlohmann::json& value) {
  if (value.is_string()) return value.get<std::string>();
  if (value.is_number_float()) return fmt::format("{}", value.get<double>());
  return value.dump();  // integers, booleans
}

std::optional<double> number(const std::string& text) {
  if (text.empty()) return std::numeric_limits<double>::quiet_NaN();
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(text.c_str(), &end);
  if (end != text.c_str() + text.size() || errno == ERANGE) return std::nullopt;
  return v;
}

bool has_finished(const Point& p) {
  return p.state.status == PointStatus::finished || p.state.status == PointStatus::invalid_results;
}

// The names (without .csv) of the tables that any finished point wrote.
std::vector<std::string> table_names(const fs::path& dir, const std::vector<Point>& points) {
  std::set<std::string> names;
  for (const Point& p : points) {
    if (!has_finished(p)) continue;
    for (const auto& entry : fs::directory_iterator(dir / p.directory)) {
      if (entry.is_regular_file() && entry.path().extension() == ".csv") {
        names.insert(entry.path().stem().string());
      }
    }
  }
  return {names.begin(), names.end()};
}

Table collect_table(const fs::path& dir, const std::vector<std::string>& keys,
                    const std::vector<Point>& points, const std::string& name) {
  Table table;
  table.columns = {"point", "status"};
  table.columns.insert(table.columns.end(), keys.begin(), keys.end());
  const std::size_t leading = table.columns.size();
  std::map<std::string, std::size_t> position;  // a point's column -> column of the table
  const auto column_of = [&](const std::string& column) {
    const auto [it, added] = position.try_emplace(column, table.columns.size());
    if (added) table.columns.push_back(column);
    return it->second;
  };
  for (const Point& p : points) {
    std::vector<std::string> front = {std::to_string(p.index), status_name(p.state.status)};
    front.insert(front.end(), p.parameters.begin(), p.parameters.end());
    const fs::path file = dir / p.directory / (name + ".csv");
    std::error_code ec;
    if (!has_finished(p) || !fs::is_regular_file(file, ec)) {
      table.rows.push_back(front);  // listed, with empty cells
      continue;
    }
    const io::CsvTable csv = io::read_csv(file);
    std::vector<std::size_t> target;
    target.reserve(csv.columns.size());
    for (const std::string& c : csv.columns) target.push_back(column_of(c));
    if (csv.rows.empty()) table.rows.push_back(front);
    for (const auto& cells : csv.rows) {
      std::vector<std::string> row = front;
      row.resize(leading);
      for (std::size_t c = 0; c < cells.size(); ++c) {
        if (row.size() <= target[c]) row.resize(target[c] + 1);
        row[target[c]] = cells[c];
      }
      table.rows.push_back(std::move(row));
    }
  }
  for (auto& row : table.rows) row.resize(table.columns.size());
  return table;
}

Table points_table(const std::vector<std::string>& keys, const std::vector<Point>& points) {
  Table table;
  table.columns = {"point", "directory", "status", "exit_status", "message"};
  table.columns.insert(table.columns.end(), keys.begin(), keys.end());
  for (const Point& p : points) {
    std::vector<std::string> row = {
        std::to_string(p.index), p.directory, status_name(p.state.status),
        p.state.exit_status < 0 ? std::string() : std::to_string(p.state.exit_status),
        p.state.message};
    row.insert(row.end(), p.parameters.begin(), p.parameters.end());
    table.rows.push_back(std::move(row));
  }
  return table;
}

fs::path temporary_for(const fs::path& file) {
  return fmt::format("{}.tmp-{}", file.string(), ::getpid());
}

void write_csv(const fs::path& file, const Table& table) {
  const fs::path temporary = temporary_for(file);
  {
    io::CsvWriter out(temporary, table.columns);
    for (const auto& row : table.rows) {
      std::vector<io::CsvWriter::Cell> cells(row.begin(), row.end());
      out.row_cells(cells);
    }
    out.close();
  }
  fs::rename(temporary, file);
}

// Each column as float64 when every cell is a number or empty (NaN), else as strings. A name
// with '/' (an HDF5 path separator) gets '_' instead.
void write_group(io::Hdf5File& h5, const std::string& group, const Table& table) {
  h5.create_group("/" + group);
  for (std::size_t c = 0; c < table.columns.size(); ++c) {
    std::string name = table.columns[c];
    std::replace(name.begin(), name.end(), '/', '_');
    const std::string path = fmt::format("/{}/{}", group, name);
    std::vector<double> numbers;
    std::vector<std::string> texts;
    bool numeric = true;
    for (const auto& row : table.rows) {
      texts.push_back(row[c]);
      const auto v = number(row[c]);
      numeric = numeric && v.has_value();
      if (v) numbers.push_back(*v);
    }
    if (numeric && !table.rows.empty()) {
      h5.write_vector(path, numbers, "");
    } else {
      h5.write_string_vector(path, texts);
    }
  }
  h5.write_string_attribute("/" + group, "columns",
                            fmt::format("{}", fmt::join(table.columns, "\n")));
}

}  // namespace

CollectResult collect(const fs::path& dir) {
  const nlohmann::json record = read_sweep_record(dir);
  const auto keys = record.at("keys").get<std::vector<std::string>>();
  const std::size_t count = record.at("points").size();
  std::vector<Point> points;
  CollectResult result;
  for (const auto& entry : record.at("points")) {
    Point p;
    p.index = entry.at("index").get<std::size_t>();
    p.directory = point_name(p.index, count);
    p.state = point_state(dir, p.index, count);
    for (const std::string& key : keys)
      p.parameters.push_back(cell_text(entry.at("parameters").at(key)));
    switch (p.state.status) {
      case PointStatus::invalid_results:
        ++result.invalid_results;
        [[fallthrough]];
      case PointStatus::finished:
        ++result.finished;
        break;
      case PointStatus::failed:
        ++result.failed;
        break;
      case PointStatus::pending:
        ++result.pending;
        break;
    }
    points.push_back(std::move(p));
  }

  std::vector<std::pair<std::string, Table>> tables;
  tables.emplace_back("points", points_table(keys, points));
  for (const std::string& name : table_names(dir, points)) {
    if (name == "points") continue;  // cannot happen for mresim's runs; keep the names unique
    tables.emplace_back(name, collect_table(dir, keys, points, name));
  }

  for (const auto& [name, table] : tables) {
    const fs::path file = dir / fmt::format("collected_{}.csv", name);
    write_csv(file, table);
    result.written.push_back(file);
  }
  const fs::path h5_file = dir / "collected.h5";
  const fs::path temporary = temporary_for(h5_file);
  {
    io::Hdf5File h5(temporary);
    h5.write_string_attribute("/", "parameters", fmt::format("{}", fmt::join(keys, "\n")));
    h5.write_string_attribute("/", "sweep", record.dump(1));
    for (const auto& [name, table] : tables) write_group(h5, name, table);
    h5.close();
  }
  fs::rename(temporary, h5_file);
  result.written.push_back(h5_file);
  return result;
}

}  // namespace mresim::sweep
