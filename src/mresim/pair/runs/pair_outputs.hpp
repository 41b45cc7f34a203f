#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "mresim/app/info_report.hpp"
#include "mresim/app/invalid_results.hpp"
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

// Whether every number of a state (separation, moment, energy terms) is finite: the `valid`
// column of summary.csv and /cases/<i>/valid.
bool state_is_finite(const PairState& state);

// Flags each state of `loop` with a non-finite number in `check` ("energy at case 0 (label),
// step 3 (B = 0.04 T)"), and non-finite critical fields.
void check_loop(app::ResultCheck& check, std::size_t case_index, const PairSetup& setup,
                const HysteresisLoop& loop);
void check_critical_fields(app::ResultCheck& check, const std::string& where,
                           const CriticalFields& fields);
// Flags critical fields that are not valid (CriticalFields::valid(): a relaxation used in
// locating them did not converge, or H_C1 is not in the swept range), naming the problem.
void check_critical_fields_valid(app::ResultCheck& check, const std::string& where,
                                 const CriticalFields& fields);

// Prints each read-time warning as "mresim: warning: ..." on stderr and returns them.
void print_warnings(const std::vector<std::string>& warnings);
// Root attribute "warnings" of results.h5: the warnings, one per line ("" when none).
void write_warnings_attribute(io::Hdf5File& h5, const std::vector<std::string>& warnings);

// The zero-field separation of the pair (m): the root of (k12 + k0/2)(S - S0) + dP/dS = 0
// next to S0 (at B = 0 the moments vanish; the penalty may push the pair out of S0).
double zero_field_separation(const PairSystem& p);

// The warning for a separation S0 inside the WCA cut-off (empty when there is none): the
// penalty pushes the pair out, so at zero field it sits at zero_field_separation(), not at S0.
// `key` names where S0 came from ("springs.rest_separation", "map.separation_min").
std::string wca_cutoff_warning(const std::string& key, const std::vector<double>& separations,
                               const PairSetup& setup);

// Number of states that did not converge, for warnings.
std::size_t unconverged_states(const HysteresisLoop& loop);

}  // namespace mresim::pair::runs
