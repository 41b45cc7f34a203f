#include "mresim/app/stop_signal.hpp"

#include <unistd.h>

#include <atomic>
#include <csignal>
#include <cstring>

namespace mresim::app {

namespace {

std::atomic<int> requested{0};
static_assert(std::atomic<int>::is_always_lock_free, "used from a signal handler");

extern "C" void on_stop_signal(int signal) {
  if (requested.exchange(signal) != 0) {
    // Second signal: the user does not want to wait.
    std::signal(signal, SIG_DFL);
    std::raise(signal);
    return;
  }
  constexpr char kNote[] =
      "\nmresim: stopping at the next safe point (send the signal again to stop at once)\n";
  const ssize_t ignored = ::write(STDERR_FILENO, kNote, sizeof kNote - 1);
  (void)ignored;
}

}  // namespace

void install_stop_handlers() {
  struct sigaction action {};
  action.sa_handler = on_stop_signal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESTART;
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
}

int stop_signal() { return requested.load(std::memory_order_relaxed); }

void clear_stop_request() { requested.store(0); }

std::string signal_name(int signal) {
  switch (signal) {
    case SIGINT:
      return "SIGINT";
    case SIGTERM:
      return "SIGTERM";
    default:
      return "signal " + std::to_string(signal);
  }
}

void throw_if_stop_requested(const std::string& where) {
  const int signal = stop_signal();
  if (signal != 0) throw Interrupted(signal, false, where);
}

}  // namespace mresim::app
