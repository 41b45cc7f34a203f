#pragma once

namespace mresim::cli {

// Exit statuses of the `mresim` command (documented in docs/cli.md).
enum ExitStatus : int {
  kSuccess = 0,
  kFailure = 1,         // the computation or writing failed; nothing was left on disk
  kInvalidInput = 2,    // bad run file, bad command line or refused --out; nothing was done
  kPlotFailed = 3,      // `mresim run`: results were written, but the figures were not
  kInvalidResults = 4,  // results were written, but some are non-finite or unconverged (marked)
};

}  // namespace mresim::cli
