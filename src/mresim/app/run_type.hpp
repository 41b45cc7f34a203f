#pragma once

#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "mresim/app/info_report.hpp"
#include "mresim/app/progress.hpp"
#include "mresim/config/table_reader.hpp"
#include "mresim/io/hdf5_file.hpp"

namespace mresim::app {

// A fully validated run, ready to describe or execute. Built by a run type's PlanFactory from
// the run file; holds every parameter it needs, so execute() never reads the file again.
class RunPlan {
 public:
  virtual ~RunPlan() = default;

  // `mresim info`: add every derived quantity (reduced fields, stiffnesses, step counts,
  // thresholds...) without computing results.
  virtual void describe(InfoReport& report) const = 0;

  // `mresim run`: compute and write. `staging_dir` is the (not yet committed) output directory
  // for extra files such as summary.csv; `results` is staging_dir/results.h5, already holding
  // the run metadata. Report work through `progress` (set_total, then advance). Throwing leaves
  // nothing on disk.
  virtual void execute(const std::filesystem::path& staging_dir, io::Hdf5File& results,
                       Progress& progress) const = 0;

  // `mpirun -np P mresim run` (or `resume`) with P > 1 (docs/mpi.md) needs a plan that splits
  // its work over the processes: rank 0 calls execute(), every other process calls
  // participate() at the same time (the same computation, writing nothing); `staging_dir` is
  // rank 0's staging directory when it resumes from a checkpoint there, else empty. Plans that
  // cannot keep these defaults; the commands then refuse to run under mpirun.
  [[nodiscard]] virtual bool splits_over_processes() const { return false; }
  // Plans that stop at safe points of their own (the 3D run types: at a step boundary, with a
  // checkpoint, ending with Interrupted{resumable = true}) return true. When their execute()
  // returns, the computation is complete: a stop signal that came after its last safe point
  // (during the last step, or while the results were written) does not discard it; the results
  // are published and the command says so. Default false: a stop signal ends the run after
  // execute(), publishing nothing (stop_signal.hpp).
  [[nodiscard]] virtual bool stops_at_own_safe_points() const { return false; }
  // Default: throws std::logic_error.
  virtual void participate(const std::filesystem::path& staging_dir) const;
};

// Reads and validates the run type's own tables from the whole document and returns the plan.
// Must read every key it accepts (that is what makes unknown keys detectable) and throw
// config::ConfigError for bad input.
using PlanFactory = std::function<std::unique_ptr<RunPlan>(const config::TableReader& root)>;

struct RunType {
  std::string name;     // the value of [run].type
  std::string summary;  // one line, shown by `mresim types` and `mresim run --help`
  PlanFactory make_plan;
};

// Adds a run type; run types register themselves at program start from their own .cpp file:
//
//   namespace {
//   // File-local names are unique across files (<file>_registrar): unity builds merge files.
//   const mresim::app::RunTypeRegistrar hysteresis_run_registrar({
//       "pair_hysteresis", "Two-dipole hysteresis loop",
//       [](const mresim::config::TableReader& root) { return std::make_unique<MyPlan>(root); }});
//   }
//
// Registering the same name twice aborts the program at start-up (a build mistake).
// This works because the executables link libmresim with WHOLE_ARCHIVE (see CMakeLists.txt);
// without it the linker would drop object files nobody references, registrars included.
void register_run_type(RunType type);

struct RunTypeRegistrar {
  explicit RunTypeRegistrar(RunType type) { register_run_type(std::move(type)); }
};

// All registered run types, sorted by name.
const std::vector<RunType>& run_types();
// nullptr if no run type has this name.
const RunType* find_run_type(std::string_view name);

// The common [run] table.
struct RunSettings {
  std::string type;   // [run].type, one of the registered names
  std::string title;  // [run].title, free text for plots and metadata ("" if absent)
  long threads = 0;   // [run].threads, >= 0; 0 = all cores
};
RunSettings read_run_settings(const config::TableReader& root);

// Reads [run], builds the plan of the chosen run type, then rejects unknown keys anywhere in the
// document. Throws config::ConfigError for any problem in the file. `run_type_name` (optional)
// receives [run].type.
std::unique_ptr<RunPlan> make_plan(const config::TableReader& root,
                                   std::string* run_type_name = nullptr);

}  // namespace mresim::app
