// A run file validated into a run plan, described (`mresim info`) and executed into a run
// directory exactly as `mresim run` does (cli::execute_and_publish), with the GIL released
// while it computes.

#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <csignal>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "bindings.hpp"
#include "cli/commands.hpp"
#include "cli/exit_status.hpp"
#include "config_source.hpp"
#include "mresim/app/command_line.hpp"
#include "mresim/app/info_report.hpp"
#include "mresim/app/run_type.hpp"
#include "mresim/app/stop_signal.hpp"
#include "mresim/app/threads.hpp"
#include "mresim/config/table_reader.hpp"
#include "mresim/io/run_directory.hpp"

namespace py = pybind11;

namespace mresim::python {

namespace {

// While a run computes, SIGINT (Ctrl-C, a notebook's "interrupt") and SIGTERM ask it to stop
// at its next safe point, as on the command line; Python's own handlers come back afterwards.
class StopHandlersDuringRun {
 public:
  StopHandlersDuringRun() {
    sigaction(SIGINT, nullptr, &interrupt_);
    sigaction(SIGTERM, nullptr, &terminate_);
    app::clear_stop_request();
    app::install_stop_handlers();
  }
  ~StopHandlersDuringRun() {
    sigaction(SIGINT, &interrupt_, nullptr);
    sigaction(SIGTERM, &terminate_, nullptr);
    app::clear_stop_request();
  }
  StopHandlersDuringRun(const StopHandlersDuringRun&) = delete;
  StopHandlersDuringRun& operator=(const StopHandlersDuringRun&) = delete;
  StopHandlersDuringRun(StopHandlersDuringRun&&) = delete;
  StopHandlersDuringRun& operator=(StopHandlersDuringRun&&) = delete;

 private:
  struct sigaction interrupt_ {};
  struct sigaction terminate_ {};
};

class PythonRunPlan {
 public:
  PythonRunPlan(const py::handle& source, const std::vector<std::string>& overrides)
      : root_(read_config(source, overrides)), plan_(app::make_plan(root_, &run_type_)) {}

  [[nodiscard]] const std::string& run_type() const { return run_type_; }
  [[nodiscard]] const std::string& toml() const { return root_.source_text(); }
  [[nodiscard]] const std::string& source_name() const { return root_.source_name(); }

  // The report of `mresim info --json` (src/cli/info_command.cpp builds the same entries).
  [[nodiscard]] std::string info_json() const {
    const app::RunSettings settings = app::read_run_settings(root_);
    app::InfoReport report;
    report.add_text("run", "file", root_.source_name());
    if (!root_.overrides().empty()) {
      std::string applied;
      for (const std::string& o : root_.overrides()) applied += (applied.empty() ? "" : "; ") + o;
      report.add_text("run", "overrides", applied, "--set, applied in this order");
    }
    report.add_text("run", "type", run_type_);
    if (!settings.title.empty()) report.add_text("run", "title", settings.title);
    report.add_integer("run", "threads", settings.threads, "", "0 = all cores");
    plan_->describe(report);
    return report.to_json().dump();
  }

  // Runs into `out` (created; an earlier mresim run there is replaced, anything else refused
  // unless `force`) and returns `mresim run`'s exit status, 0, 3 (figures failed), 4 (invalid
  // results, written and marked) or 128 + signal (stopped; a 3D run keeps its checkpoint), and
  // whether the results were published (also after a signal that came during a 3D run's last
  // step: RunPlan::stops_at_own_safe_points).
  std::pair<int, bool> execute(const std::string& out, long threads, bool force, bool plot) const {
    record_python_command_line();
    const py::gil_scoped_release computing;
    io::RunDirectory run_dir(out, io::RunDirectory::Options{force});
    const StopHandlersDuringRun stop_handlers;
    const int status = cli::execute_and_publish(root_, *plan_, run_type_, run_dir, threads, !plot);
    return {status, run_dir.committed()};
  }

 private:
  // Provenance (results.h5 command_line): the Python interpreter and its sys.argv, since a run
  // from Python has no mresim command line of its own.
  static void record_python_command_line() {
    const py::module_ sys = py::module_::import("sys");
    std::vector<std::string> words{sys.attr("executable").cast<std::string>()};
    for (const py::handle word : sys.attr("argv"))
      words.push_back(py::str(word).cast<std::string>());
    std::vector<const char*> argv;
    argv.reserve(words.size());
    for (const std::string& word : words) argv.push_back(word.c_str());
    app::set_command_line(static_cast<int>(argv.size()), argv.data());
  }

  config::TableReader root_;
  std::string run_type_;
  std::unique_ptr<app::RunPlan> plan_;
};

}  // namespace

void bind_run_plan(py::module_& m) {
  py::class_<PythonRunPlan>(m, "RunPlan",
                            "A validated run file (use mresim.Run; this is its compiled part)")
      .def(py::init<const py::handle&, const std::vector<std::string>&>(), py::arg("source"),
           py::arg("overrides") = std::vector<std::string>{})
      .def_property_readonly("run_type", &PythonRunPlan::run_type)
      .def_property_readonly("toml", &PythonRunPlan::toml)
      .def_property_readonly("source_name", &PythonRunPlan::source_name)
      .def("info_json", &PythonRunPlan::info_json)
      .def("execute", &PythonRunPlan::execute, py::arg("out"), py::arg("threads") = -1,
           py::arg("force") = false, py::arg("plot") = false);

  m.def(
      "run_types",
      [] {
        std::vector<std::pair<std::string, std::string>> types;
        for (const app::RunType& t : app::run_types()) types.emplace_back(t.name, t.summary);
        return types;
      },
      "(name, summary) of every run type in this build, as `mresim types` lists them");
  m.def("max_threads", &app::max_threads);
  m.def("threads_allowed", &app::threads_allowed,
        "What --threads accepts, as the command line says it");
  m.attr("EXIT_INVALID_RESULTS") = static_cast<int>(cli::kInvalidResults);
  m.attr("EXIT_PLOT_FAILED") = static_cast<int>(cli::kPlotFailed);
}

}  // namespace mresim::python
