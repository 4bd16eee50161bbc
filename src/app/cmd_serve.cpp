// `panoptes serve DB`: serves a movie database and the web player over HTTP (docs/web.md).
#include <pthread.h>
#include <signal.h>
#include <sys/resource.h>

#include <atomic>
#include <cctype>
#include <cstdlib>
#include <ctime>
#include <cstdio>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "app/command.hpp"
#include "core/error.hpp"
#include "web/server.hpp"

namespace cmd_serve {  // named, not anonymous: the unity build joins the command units

// How long Ctrl+C waits for the server's threads before the process ends without them: longer than
// the server's timeouts (5 s), so a normal stop always ends by itself.
constexpr int kStopSeconds = 8;

struct Args {
  std::string db;
  int port = 8080;
  std::string bind = "127.0.0.1";
  std::string token;
  int threads = 16;
  int max_connections = 1024;
  bool quiet = false;
};

void run(const Args& a) {
  using namespace panoptes;
  // The token goes into a URL and a cookie as it is: keep it to characters that need no escaping.
  for (char ch : a.token)
    if (!std::isalnum(static_cast<unsigned char>(ch)) && ch != '-' && ch != '_' && ch != '.' && ch != '~')
      throw Error("--token \"" + a.token + "\": expected letters, digits and - _ . ~ only");
  web::ServerOptions o;
  o.database = a.db;
  o.player_dir = web::find_player_dir();
  o.bind = a.bind;
  o.port = a.port;
  o.token = a.token;
  o.threads = a.threads;
  o.max_connections = a.max_connections;
  auto out_mutex = std::make_shared<std::mutex>();
  if (!a.quiet)
    o.log = [out_mutex](const std::string& line) {
      std::lock_guard lock(*out_mutex);
      std::printf("%s\n", line.c_str());
      std::fflush(stdout);
    };
  // SIGINT/SIGTERM are waited for by one thread (sigwait) that stops the server: httplib's stop() is
  // not async-signal-safe, so it must not run in a signal handler. Blocked before any thread starts.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  // A connection is a socket and, while it sends a file, a descriptor more: let --max-connections of
  // them open without EMFILE (the soft limit is often 1024; the hard one is the administrator's).
  rlimit files{};
  if (getrlimit(RLIMIT_NOFILE, &files) == 0 && files.rlim_cur < files.rlim_max) {
    files.rlim_cur = files.rlim_max;
    setrlimit(RLIMIT_NOFILE, &files);
  }
  web::Server server(o);
  std::string url = server.url();
  if (!a.token.empty()) url += "?token=" + a.token;
  std::printf("serving %s (read-only) at %s\n", a.db.c_str(), url.c_str());
  if (a.bind != "127.0.0.1" && a.bind != "localhost" && a.bind != "::1" && a.token.empty())
    std::printf("warning: listening on %s without --token: anyone who can reach this port can read the database\n",
                a.bind.c_str());
  std::printf("Ctrl+C stops the server\n");
  std::fflush(stdout);
  std::atomic<bool> ran{false};
  std::thread waiter([&server, &ran, signals] {
    int sig = 0;
    sigwait(&signals, &sig);
    if (ran) return;  // woken by the main thread after run() returned by itself
    server.stop();
    // stop() cuts every connection within 100 ms of its next wait (web/bounded_http_server.hpp), so
    // run() returns at once unless a handler is busy (indexing a huge movie, say). Should it still not
    // return in time, or on a second Ctrl+C, the process ends anyway: Ctrl+C stops the server whatever
    // its threads are doing (issue 31).
    const timespec wait{kStopSeconds, 0};
    sigtimedwait(&signals, nullptr, &wait);  // a second signal, the main thread's wake-up or the deadline
    if (!ran) {
      std::printf("stopped (connections still open were cut)\n");
      std::fflush(stdout);
      std::_Exit(0);
    }
  });
  server.run();
  ran = true;
  // run() may also return without a signal (a listen error): wake the waiter so it can be joined.
  pthread_kill(waiter.native_handle(), SIGTERM);
  waiter.join();
  std::printf("stopped\n");
}

panoptes::app::CommandRegistration reg([](CLI::App& root) {
  auto args = std::make_shared<Args>();
  auto* sub = root.add_subcommand(
      "serve",
      "Serve a movie database and the web player over HTTP (read-only): open the printed URL in a browser. "
      "Movies are served with byte ranges; nothing outside the database can be reached");
  sub->add_option("DB", args->db, "Database directory")->required()->check(CLI::ExistingDirectory);
  sub->add_option("--port", args->port, "TCP port (0 = any free port)")->check(CLI::Range(0, 65535))->capture_default_str();
  sub->add_option("--bind", args->bind, "Address to listen on (0.0.0.0 = every interface; use with --token)")
      ->capture_default_str();
  sub->add_option("--token", args->token, "Require this token: open the URL with ?token=T (sets a cookie) or send "
                                          "'Authorization: Bearer T'");
  sub->add_option("--threads", args->threads, "Threads kept ready for connections (more start on demand)")
      ->check(CLI::Range(1, 1024))
      ->capture_default_str();
  sub->add_option("--max-connections", args->max_connections,
                  "Connections served at once (a thread each); later ones wait their turn")
      ->check(CLI::Range(1, 65536))
      ->capture_default_str();
  sub->add_flag("--quiet", args->quiet, "No log line per request");
  sub->callback([args] { run(*args); });
});

}  // namespace
