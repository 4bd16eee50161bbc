#pragma once
// `panoptes serve`: a read-only HTTP server (cpp-httplib) for one movie database and the web player.
//
//   GET /                          the player (index.html and its files from the player directory)
//   GET /api/database.json         the database as JSON (web/database_json.hpp), re-read per request
//   GET /api/index/C/T.json        fragment index of the movie of camera C, task T; for a packed
//                                  database the ranges of its packs (files, init, fragments with
//                                  their file), built once per opened manifest and then cached
//   GET /db/PATH                   a file of the database, with byte ranges (Range: bytes=a-b → 206):
//                                  a packed database's streams are read straight from db/packs/*.pack
//
// Nothing outside the database and the player directory can be reached (web/safe_path.hpp); with a
// token, every request must carry it (?token=T once, which sets a cookie, or Authorization: Bearer T).
//
// Hostile clients (issue 31): request heads are read within bounds of bytes, lines and time
// (web/bounded_http_server.hpp); the token is checked first, before anything else of a request is
// used; a request with a body is refused (413, connection closed) without reading it, since nothing
// here takes one; a client idle or not reading for `timeout_seconds` is dropped; each connection has
// a thread of its own up to `max_connections` (web/connection_threads.hpp), so slow or idle clients
// do not starve the rest; the listen backlog is kListenBacklog, TCP_NODELAY is set, and what a client
// sent is escaped before it reaches the log.
#include <cstddef>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <string_view>

namespace panoptes::web {

/// How to serve.
struct ServerOptions {
  std::filesystem::path database;    ///< database directory
  std::filesystem::path player_dir;  ///< directory holding index.html and the player's files
  std::string bind = "127.0.0.1";    ///< address to listen on; localhost unless told otherwise
  int port = 8080;                   ///< 0 = any free port (see Server::port())
  std::string token;                 ///< empty = no token required
  int threads = 16;                  ///< threads kept ready for connections
  int max_connections = 1024;        ///< connections served at once (a thread each); later ones wait
  int timeout_seconds = 5;           ///< a client idle (or not reading) this long is dropped; a request
                                     ///< head must arrive within twice this
  /// Receives one line per request and per refusal (no trailing newline); empty = silent.
  std::function<void(const std::string&)> log;
};

/// The listen backlog (cpp-httplib's own is 5: a burst of clients beyond that waited for SYN retries).
inline constexpr int kListenBacklog = 1024;
/// Times listed per database.json response (`?times_from=N` gives the next page).
inline constexpr std::size_t kTimesPerPage = 65536;

/// What a client sent, made safe for a one-line log: control characters, backslashes and bytes
/// outside printable ASCII become \xNN (so "%0a" in a path cannot start a forged log line), and
/// more than `max` bytes are cut with the count of the rest.
std::string escape_for_log(std::string_view text, std::size_t max = 512);

/// An HTTP server bound to its address from construction until destruction.
class Server {
 public:
  /// Opens the database (manifest only), checks the player directory and binds the socket. Throws
  /// FileError for a bad database or player directory, Error if the address cannot be bound.
  explicit Server(ServerOptions options);
  ~Server();
  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;

  /// The bound port (the chosen one when options.port was 0).
  int port() const;
  /// "http://HOST:PORT/".
  std::string url() const;
  /// Serves until stop() is called (from another thread).
  void run();
  /// Makes run() return; safe from any thread. Connections being served are cut at their next
  /// read, write or 64 kB of a file sent, so run() returns within about `timeout_seconds`.
  void stop();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// The player's files: $PANOPTES_WEB_DIR if set, else share/panoptes/web next to the executable's
/// bin/ directory (build tree and install tree alike). Throws Error naming the places tried when
/// none holds index.html.
std::filesystem::path find_player_dir();

}  // namespace panoptes::web
