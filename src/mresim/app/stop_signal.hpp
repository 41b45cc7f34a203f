#pragma once

#include <stdexcept>
#include <string>

namespace mresim::app {

// SIGINT (Ctrl-C) and SIGTERM (what Slurm sends at the end of a job's time, or `scancel`) ask a
// run to stop at its next safe point instead of dying mid-write. The 3D run types then write a
// checkpoint and end with Interrupted{resumable = true} (a signal during their last step finds
// no safe point left: their complete results are published, RunPlan::stops_at_own_safe_points);
// run types without checkpoints end with resumable = false and publish nothing. A second signal
// ends the process at once (the default action), for a user who does not want to wait.
//
// `mresim run`/`resume` exit with 128 + the signal number (130 for SIGINT, 143 for SIGTERM),
// the shell's convention for "ended by this signal".

// Installs the handlers (once, from main thread, before the run starts).
void install_stop_handlers();

// The signal that asked to stop, or 0.
int stop_signal();
inline bool stop_requested() { return stop_signal() != 0; }

// "SIGINT", "SIGTERM".
std::string signal_name(int signal);

// For tests: forget a request.
void clear_stop_request();

struct Interrupted : std::runtime_error {
  Interrupted(int signal_number, bool can_resume, const std::string& where)
      : std::runtime_error(where), signal(signal_number), resumable(can_resume) {}
  int signal;
  bool resumable;  // a checkpoint was written: `mresim resume` continues the run
};

// Throws Interrupted(resumable = false) if a stop was requested; a safe point of run types that
// write no checkpoint. Not inside an OpenMP parallel region.
void throw_if_stop_requested(const std::string& where);

}  // namespace mresim::app
