#include "mresim/pair/parameter_map.hpp"

#include "mresim/core/parallel_exceptions.hpp"

namespace mresim::pair {

CriticalFieldGrid map_critical_fields(std::size_t rows, std::size_t cols,
                                      const MapPointBuilder& point,
                                      const CriticalFieldOptions& options,
                                      const std::function<void()>& on_point_done) {
  CriticalFieldGrid grid;
  grid.rows = rows;
  grid.cols = cols;
  grid.fields.resize(rows * cols);
  const auto count = static_cast<long>(rows * cols);
  // Points near the clustering threshold take several times longer: dynamic scheduling.
  ParallelExceptions errors;  // no exception may leave the parallel region
#pragma omp parallel for schedule(dynamic, 1)
  for (long index = 0; index < count; ++index) {
    errors.run([&] {
      const auto i = static_cast<std::size_t>(index);
      const MapPointSetup setup = point(i / cols, i % cols);
      grid.fields[i] = critical_fields_of(setup.system, setup.sweep, options);
      if (on_point_done) on_point_done();
    });
  }
  errors.rethrow();
  return grid;
}

}  // namespace mresim::pair
