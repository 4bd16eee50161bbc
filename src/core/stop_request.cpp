#include "core/stop_request.hpp"

#include <signal.h>

#include <atomic>
#include <csignal>

namespace panoptes {

namespace {

volatile std::sig_atomic_t g_stop = 0;
std::atomic<bool> g_installed{false};

extern "C" void on_stop_signal(int sig) {
  if (g_stop != 0) {
    // Second signal: the user means it. Default action, re-raised (exit status shows the signal).
    ::signal(sig, SIG_DFL);
    ::raise(sig);
    return;
  }
  g_stop = sig;
}

}  // namespace

void install_stop_handlers() {
  if (g_installed.exchange(true)) return;
  struct sigaction sa{};
  sa.sa_handler = on_stop_signal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = SA_RESTART;  // writes and waits in progress continue; the writer polls between snapshots
  ::sigaction(SIGINT, &sa, nullptr);
  ::sigaction(SIGTERM, &sa, nullptr);
}

int stop_requested() { return int(g_stop); }

void request_stop(int signal) { g_stop = signal; }

void clear_stop_request() { g_stop = 0; }

std::string signal_name(int signal) {
  if (signal == SIGINT) return "SIGINT";
  if (signal == SIGTERM) return "SIGTERM";
  return "signal " + std::to_string(signal);
}

}  // namespace panoptes
