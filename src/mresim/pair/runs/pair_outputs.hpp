#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "mresim/app/info_report.hpp"
#include "mresim/io/csv_writer.hpp"
#include "mresim/io/hdf5_file.hpp"
#include "mresim/pair/critical_fields.hpp"
#include "mresim/pair/runs/pair_setup.hpp"

// Writing two-dipole results: per-step tables (summary.csv and /cases/<i>/ in results.h5) and
// the quantities `mresim info` reports for a pair. Column meanings: docs/run-files.md.
namespace mresim::pair::runs {

// Columns of summary.csv for loops (one row per field step, all cases stacked).
std::vector<std::string> loop_csv_columns();

void append_loop_rows(io::CsvWriter& csv, std::size_t case_index, const PairSetup& setup,
                      const HysteresisLoop& loop);

void write_loop_hdf5(io::Hdf5File& h5, const std::string& group, const PairSetup& setup,
                     const PairSystem& system, const HysteresisLoop& loop);

void write_critical_fields_hdf5(io::Hdf5File& h5, const std::string& group,
                                const CriticalFields& fields);

// The pair's parameters and derived quantities (V, k, k0, k12, E <-> k, eq. 2.10) for `info`.
void describe_pair(app::InfoReport& report, const std::string& section, const PairSetup& setup);

// Number of states that did not converge, for warnings.
std::size_t unconverged_states(const HysteresisLoop& loop);

}  // namespace mresim::pair::runs
