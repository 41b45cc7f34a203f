#pragma once

#include <functional>
#include <vector>

#include "mresim/pair/critical_fields.hpp"

namespace mresim::pair {

// One grid point of a critical-field map: the pair and the sweep to run there.
struct MapPointSetup {
  PairSystem system;
  SweepOptions sweep;
};

// Critical fields over a rows x cols grid (Fig. 2.5: k x S0; Fig. 2.9: theta_H x S0), one
// first-quadrant sweep with refined critical fields per point. Points run in parallel with
// OpenMP; each result depends only on its own point, so the map is the same for any number
// of threads. Results are row-major: index = row * cols + col.
struct CriticalFieldGrid {
  std::size_t rows = 0;
  std::size_t cols = 0;
  std::vector<CriticalFields> fields;
  const CriticalFields& at(std::size_t row, std::size_t col) const {
    return fields[row * cols + col];
  }
};

using MapPointBuilder = std::function<MapPointSetup(std::size_t row, std::size_t col)>;

CriticalFieldGrid map_critical_fields(std::size_t rows, std::size_t cols,
                                      const MapPointBuilder& point,
                                      const CriticalFieldOptions& options,
                                      const std::function<void()>& on_point_done = {});

}  // namespace mresim::pair
