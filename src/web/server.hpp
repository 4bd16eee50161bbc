#pragma once
// `panoptes serve`: a read-only HTTP server (cpp-httplib) for one movie database and the web player.
//
//   GET /                          the player (index.html and its files from the player directory)
//   GET /api/database.json         the database as JSON (web/database_json.hpp), re-read per request
//   GET /api/index/C/T.json        fragment index of the movie of camera C, task T
//   GET /db/PATH                   a file of the database, with byte ranges (Range: bytes=a-b → 206)
//
// Nothing outside the database and the player directory can be reached (web/safe_path.hpp); with a
// token, every request must carry it (?token=T once, which sets a cookie, or Authorization: Bearer T).
#include <filesystem>
#include <functional>
#include <memory>
#include <string>

namespace panoptes::web {

/// How to serve.
struct ServerOptions {
  std::filesystem::path database;    ///< database directory
  std::filesystem::path player_dir;  ///< directory holding index.html and the player's files
  std::string bind = "127.0.0.1";    ///< address to listen on; localhost unless told otherwise
  int port = 8080;                   ///< 0 = any free port (see Server::port())
  std::string token;                 ///< empty = no token required
  int threads = 16;                  ///< worker threads (concurrent connections served at once)
  /// Receives one line per request and per refusal (no trailing newline); empty = silent.
  std::function<void(const std::string&)> log;
};

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
  /// Makes run() return; safe from any thread.
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
