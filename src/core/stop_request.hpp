#pragma once
// Graceful stop on SIGINT / SIGTERM for long writers (`panoptes run`, `render`, `synth-db`, the
// in-situ session): the first signal only records a request, which the writer polls between
// snapshots so it can leave its database `interrupted` with every complete snapshot readable and
// its lock removed; a second signal terminates at once (the database is still consistent up to its
// last checkpoint, just still marked `running`).
#include <string>

#include "core/error.hpp"

namespace panoptes {

/// Installs the SIGINT and SIGTERM handlers (idempotent). Programs call it; the library never does.
void install_stop_handlers();

/// The signal that asked to stop (SIGINT, SIGTERM), or 0. Async-signal-safe to read.
int stop_requested();

/// Records a stop request as if `signal` had arrived (tests; a host code's own handler may call it).
void request_stop(int signal);

/// Clears a pending request (tests).
void clear_stop_request();

/// Thrown by a writer that stopped because of a signal. The command line exits with 128 + signal.
class Interrupted : public Error {
 public:
  Interrupted(int signal, const std::string& what) : Error(what), signal_(signal) {}
  int signal() const noexcept { return signal_; }

 private:
  int signal_;
};

/// "SIGINT", "SIGTERM", or "signal N".
std::string signal_name(int signal);

}  // namespace panoptes
