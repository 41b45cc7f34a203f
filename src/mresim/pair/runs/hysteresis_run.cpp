// Run type "pair_hysteresis": one or more two-dipole hysteresis loops (Figs. 2.2-2.4, 2.6-2.8,
// 3.4, 3.13), each with its critical fields.
#include <fmt/format.h>

#include <memory>

#include "mresim/app/run_output.hpp"
#include "mresim/app/run_type.hpp"
#include "mresim/core/parallel_exceptions.hpp"
#include "mresim/pair/runs/pair_outputs.hpp"

namespace mresim::pair::runs {
namespace {

class HysteresisPlan final : public app::RunPlan {
 public:
  explicit HysteresisPlan(const config::TableReader& root) : cases_(read_pair_cases(root)) {
    const bool has_cases = !root.table_list("case").empty();
    for (std::size_t i = 0; i < cases_.size(); ++i) {
      const std::string key =
          has_cases ? fmt::format("case[{}] ({}): springs.rest_separation", i, cases_[i].label)
                    : std::string("springs.rest_separation");
      const std::string w = wca_cutoff_warning(key, {cases_[i].rest_separation}, cases_[i]);
      if (!w.empty()) warnings_.push_back(w);
    }
    print_warnings(warnings_);
  }

  void describe(app::InfoReport& report) const override {
    report.add_integer("run", "cases", static_cast<std::int64_t>(cases_.size()));
    for (std::size_t i = 0; i < cases_.size(); ++i) {
      describe_pair(report, section(i), cases_[i]);
    }
  }

  void execute(const std::filesystem::path& staging_dir, io::Hdf5File& results,
               app::Progress& progress) const override {
    std::size_t total = 0;
    for (const PairSetup& c : cases_) total += sweep_points(c.sweep).size();
    progress.set_total(total);
    std::vector<HysteresisLoop> loops(cases_.size());
    std::vector<CriticalFields> fields(cases_.size());
    const auto count = static_cast<long>(cases_.size());
    ParallelExceptions errors;
#pragma omp parallel for schedule(dynamic, 1)
    for (long i = 0; i < count; ++i) {
      errors.run([&] {
        const auto c = static_cast<std::size_t>(i);
        const PairSystem system = cases_[c].system();
        loops[c] = run_hysteresis(system, cases_[c].sweep);
        CriticalFieldOptions options;
        options.tolerance = cases_[c].critical_field_tolerance;
        fields[c] = find_critical_fields(system, loops[c], options);
        progress.advance(loops[c].states.size());
      });
    }
    errors.rethrow();

    app::ResultCheck check("non-finite results");
    app::ResultCheck unmarked("critical fields not valid");
    io::CsvWriter summary(staging_dir / "summary.csv", loop_csv_columns());
    io::CsvWriter critical(
        staging_dir / "critical_fields.csv",
        {"case", "label", "hysteresis", "HC1_T", "HC2_T", "dH_T", "uncertainty_T", "valid"});
    for (std::size_t c = 0; c < cases_.size(); ++c) {
      const std::string group = fmt::format("/cases/{}", c);
      append_loop_rows(summary, c, cases_[c], loops[c]);
      write_loop_hdf5(results, group, cases_[c], cases_[c].system(), loops[c]);
      write_critical_fields_hdf5(results, group + "/critical_fields", fields[c]);
      check_loop(check, c, cases_[c], loops[c]);
      check_critical_fields(check, fmt::format("case {} ({})", c, cases_[c].label), fields[c]);
      check_critical_fields_valid(unmarked, fmt::format("case {} ({})", c, cases_[c].label),
                                  fields[c]);
      critical.row_cells({static_cast<double>(c), cases_[c].label, fields[c].hysteresis ? 1.0 : 0.0,
                          fields[c].hc1, fields[c].hc2, fields[c].delta(), fields[c].uncertainty,
                          fields[c].valid() ? 1.0 : 0.0});
      if (const std::size_t bad = unconverged_states(loops[c]); bad > 0) {
        app::warn(
            fmt::format("case {} ({}): {} of {} states did not reach the relaxation tolerance (see "
                        "solver/converged)",
                        c, cases_[c].label, bad, loops[c].states.size()));
      }
    }
    results.write_int_attribute("/cases", "count", static_cast<std::int64_t>(cases_.size()));
    write_warnings_attribute(results, warnings_);
    check.throw_if_any(
        "written as NaN; see /cases/<i>/valid in results.h5 and the valid column of summary.csv");
    unmarked.throw_if_any(
        "written with valid = 0 in critical_fields.csv and /cases/<i>/critical_fields/@valid");
  }

 private:
  std::string section(std::size_t i) const {
    return cases_.size() == 1 ? std::string("pair")
                              : fmt::format("case {}: {}", i, cases_[i].label);
  }

  std::vector<PairSetup> cases_;
  std::vector<std::string> warnings_;  // read-time warnings, also in results.h5 /@warnings
};

const app::RunTypeRegistrar hysteresis_run_registrar(
    {"pair_hysteresis",
     "Two-dipole hysteresis loops with critical fields "
     "(Chapters 2-3)",
     [](const config::TableReader& root) { return std::make_unique<HysteresisPlan>(root); }});

}  // namespace
}  // namespace mresim::pair::runs
