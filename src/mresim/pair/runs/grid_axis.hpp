#pragma once

#include <string>
#include <vector>

#include "mresim/config/table_reader.hpp"

namespace mresim::pair::runs {

// A list of parameter values given either explicitly (`<name>_values = [...]`) or as
// `<name>_min`, `<name>_max`, `<name>_count` with `<name>_spacing = "linear" | "log"`.
// Every value must lie in `allowed`. `default_spacing` is used when no spacing is given.
std::vector<double> read_grid_axis(const config::TableReader& table, const std::string& name,
                                   const config::Range& allowed, const std::string& unit,
                                   const std::string& default_spacing);

}  // namespace mresim::pair::runs
