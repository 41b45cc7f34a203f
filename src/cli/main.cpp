// The `mresim` command: parses the command line, dispatches to one command, and maps failures
// to one-line messages and exit statuses (see exit_status.hpp and docs/cli.md).

#include <CLI/CLI.hpp>
#include <cstdio>
#include <cstring>
#include <exception>
#include <mresim/core/version.hpp>
#include <new>
#include <string>

#include "cli/commands.hpp"
#include "cli/exit_status.hpp"
#include "mresim/app/allocator_arenas.hpp"
#include "mresim/app/command_line.hpp"
#include "mresim/app/run_output.hpp"
#include "mresim/app/stop_signal.hpp"
#include "mresim/config/config_error.hpp"
#include "mresim/io/run_directory.hpp"

namespace {

// On stderr and, for run and resume with --log, in the log too.
int report_error(const char* message, int status) {
  mresim::app::run_output().error(std::string("mresim: error: ") + message);
  return status;
}

int run_cli(int argc, char** argv) {
  using namespace mresim::cli;
  mresim::app::set_command_line(argc, argv);  // recorded in results.h5 (io/metadata.hpp)

  CLI::App app{
      "mresim: particle-resolved simulation of magnetorheological elastomers.\n"
      "Describe a run in a TOML file, then 'mresim run FILE'. See docs/cli.md and "
      "docs/run-files.md.",
      "mresim"};
  app.set_version_flag("--version", std::string("mresim ") + mresim::kVersion);
  app.require_subcommand(1);
  app.footer(
      "Exit status: 0 success; 1 the run failed (nothing was written); 2 invalid run file,\n"
      "command line or --out (nothing was done); 3 results written but drawing figures failed;\n"
      "4 results written but some are invalid (marked); 130/143 stopped by SIGINT/SIGTERM.");

  RunOptions run_options;
  InfoOptions info_options;
  PlotOptions plot_options;
  ResumeOptions resume_options;
  ExtendOptions extend_options;
  RerunOptions rerun_options;
  SweepOptions sweep_options;
  CollectOptions collect_options;
  CLI::App* run = add_run_command(app, run_options);
  CLI::App* resume = add_resume_command(app, resume_options);
  CLI::App* extend = add_extend_command(app, extend_options);
  CLI::App* rerun = add_rerun_command(app, rerun_options);
  CLI::App* info = add_info_command(app, info_options);
  CLI::App* plot = add_plot_command(app, plot_options);
  CLI::App* sweep = add_sweep_command(app, sweep_options);
  CLI::App* collect = add_collect_command(app, collect_options);
  CLI::App* types = add_types_command(app);

  // CLI11 would take an unknown command for a stray argument and, with --help, print the main
  // help and succeed: a typo must fail instead.
  if (argc > 1 && argv[1][0] != '-') {
    bool known = false;
    std::string names;
    for (const CLI::App* command : app.get_subcommands({})) {
      known |= command->check_name(argv[1]);
      names += (names.empty() ? "" : ", ") + command->get_name();
    }
    if (!known) {
      std::fprintf(stderr,
                   "mresim: error: unknown command '%s'; commands: %s\nRun 'mresim --help' for "
                   "usage.\n",
                   argv[1], names.c_str());
      return kInvalidInput;
    }
  }

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "mresim: error: %s\nRun 'mresim --help' for usage.\n", e.what());
    return kInvalidInput;
  }

  try {
    if (*run || *resume || *extend || *rerun || *sweep) mresim::app::install_stop_handlers();
    if (*run) return run_command(run_options);
    if (*resume) return resume_command(resume_options);
    if (*extend) return extend_command(extend_options);
    if (*rerun) return rerun_command(rerun_options);
    if (*info) return info_command(info_options);
    if (*plot) return plot_command(plot_options);
    if (*sweep) return sweep_command(sweep_options);
    if (*collect) return collect_command(collect_options);
    if (*types) return types_command();
  } catch (const mresim::config::ConfigError& e) {
    return report_error(e.what(), kInvalidInput);
  } catch (const mresim::io::OutputDirectoryError& e) {
    return report_error(e.what(), kInvalidInput);
  } catch (const std::bad_alloc&) {
    return report_error(
        "out of memory; the run needs more memory than this machine or job allows ('mresim info "
        "FILE' prints the estimate for 3D runs)",
        kFailure);
  } catch (const std::exception& e) {
    return report_error(e.what(), kFailure);
  }
  return kFailure;  // unreachable: require_subcommand(1)
}

}  // namespace

int main(int argc, char** argv) {
  // Before any thread allocates (allocator_arenas.hpp): memory freed in a worker thread then
  // serves the next allocation instead of staying resident in that thread's arena.
  (void)mresim::app::use_one_allocator_arena();
  try {
    return run_cli(argc, argv);
  } catch (const std::exception& e) {  // e.g. out of memory while setting up
    return report_error(e.what(), mresim::cli::kFailure);
  } catch (...) {
    return report_error("unknown internal error", mresim::cli::kFailure);
  }
}
