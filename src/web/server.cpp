#include "web/server.hpp"

#include "player/keys_json.hpp"

#include <httplib.h>
#include <sys/stat.h>
#include <unistd.h>

#include <sys/socket.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstring>

#include <chrono>
#include <cstdio>
#include <ctime>
#include <mutex>
#include <map>
#include <regex>
#include <stdexcept>
#include <tuple>

#include "core/error.hpp"
#include "core/utc_time.hpp"
#include "store/database.hpp"
#include "web/bounded_http_server.hpp"
#include "web/connection_threads.hpp"
#include "web/database_json.hpp"
#include "web/fragment_index_cache.hpp"
#include "web/mp4_fragments.hpp"
#include "web/safe_path.hpp"

namespace panoptes::web {

namespace fs = std::filesystem;

namespace {

std::string content_type(const fs::path& p) {
  const std::string ext = p.extension().string();
  if (ext == ".html") return "text/html; charset=utf-8";
  if (ext == ".js" || ext == ".mjs") return "text/javascript; charset=utf-8";
  if (ext == ".css") return "text/css; charset=utf-8";
  if (ext == ".json") return "application/json";
  if (ext == ".mp4") return "video/mp4";
  if (ext == ".png") return "image/png";
  if (ext == ".svg") return "image/svg+xml";
  return "application/octet-stream";
}

/// Compares without an early exit, so the time taken does not tell how much of a guess was right.
bool same_secret(const std::string& given, const std::string& token) {
  if (token.empty() || given.size() != token.size()) return false;
  unsigned char diff = 0;
  for (std::size_t i = 0; i < token.size(); ++i) diff |= static_cast<unsigned char>(given[i] ^ token[i]);
  return diff == 0;
}

std::string cookie_value(const std::string& cookies, const std::string& name) {
  std::size_t p = 0;
  while (p < cookies.size()) {
    while (p < cookies.size() && (cookies[p] == ' ' || cookies[p] == ';')) ++p;
    const std::size_t end = std::min(cookies.find(';', p), cookies.size());
    const std::string item = cookies.substr(p, end - p);
    const std::size_t eq = item.find('=');
    if (eq != std::string::npos && item.substr(0, eq) == name) return item.substr(eq + 1);
    p = end + 1;
  }
  return {};
}

/// The request as one escaped log field: method and path (decoded by httplib, so "%0a" is a newline
/// here and must not reach the log as one).
std::string request_line(const httplib::Request& req) {
  return escape_for_log(req.remote_addr, 64) + " " + escape_for_log(req.method, 16) + " " + escape_for_log(req.path);
}

void send_error(httplib::Response& res, int status, const std::string& message) {
  res.status = status;
  res.set_content(nlohmann::json{{"error", message}}.dump(), "application/json");
}

/// Serves an opened file whole or, with a Range header, the asked bytes (httplib answers 206 / 416).
/// Reads go through the descriptor opened by SafeRoot::open (pread: no shared offset, no re-open).
void send_file(httplib::Response& res, store::FileHandle file, const std::string& type,
               const std::atomic<bool>& stopping) {
  struct stat st{};
  if (::fstat(file.get(), &st) != 0) return send_error(res, 404, "cannot read the file");
  const auto size = std::size_t(st.st_size);
  res.set_header("Cache-Control", "no-cache");
  res.set_header("Accept-Ranges", "bytes");
  if (size == 0) return res.set_content("", type);
  auto fd = std::make_shared<store::FileHandle>(std::move(file));
  res.set_content_provider(size, type, [fd, &stopping](std::size_t offset, std::size_t length, httplib::DataSink& sink) {
    char buf[64 * 1024];
    while (length > 0) {
      if (stopping) return false;  // stop() cuts a long download instead of waiting for it
      const ssize_t got = ::pread(fd->get(), buf, std::min(length, sizeof buf), off_t(offset));
      if (got < 0 && errno == EINTR) continue;
      if (got <= 0 || !sink.write(buf, std::size_t(got))) return false;
      offset += std::size_t(got);
      length -= std::size_t(got);
    }
    return true;
  });
}

/// Is the request announcing a body? Nothing here takes one: it is refused before a byte of it is read.
bool has_body(const httplib::Request& req) {
  if (req.has_header("Transfer-Encoding")) return true;
  if (!req.has_header("Content-Length")) return false;
  const std::string length = req.get_header_value("Content-Length");
  return length.find_first_not_of('0') != std::string::npos;  // "0", "00": empty; anything else is not
}

}  // namespace

std::string escape_for_log(std::string_view text, std::size_t max) {
  static const char* const hex = "0123456789abcdef";
  std::string out;
  const std::size_t n = std::min(text.size(), max);
  out.reserve(n + 16);
  for (std::size_t i = 0; i < n; ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (c < 0x20 || c >= 0x7f || c == '\\') {
      out += "\\x";
      out += hex[c >> 4];
      out += hex[c & 15];
    } else {
      out += char(c);
    }
  }
  if (text.size() > n) out += "...(" + std::to_string(text.size() - n) + " more bytes)";
  return out;
}

struct Server::Impl {
  ServerOptions options;
  SafeRoot db_root, player_root;
  BoundedHttpServer http;
  int port = 0;
  std::mutex db_mutex;
  std::shared_ptr<const store::Database> db;
  // database.json as sent, per query, for the database opened now: built once per opened database
  // (issue 44: every GET re-built the JSON of the whole manifest, 5.8-7.7 s per request at 255 MB). A
  // running database is reopened at each request (database()), so its JSON is rebuilt then.
  std::mutex json_mutex;
  std::shared_ptr<const store::Database> json_db;
  std::map<std::tuple<bool, std::uint64_t, std::int64_t>, std::shared_ptr<const std::string>> json_cache;
  static constexpr std::size_t kJsonCacheEntries = 64;  // pages of times and the inline form

  std::shared_ptr<const std::string> cached_database_json(const std::shared_ptr<const store::Database>& d,
                                                         const DatabaseJsonOptions& o) {
    const auto key = std::make_tuple(o.inline_cameras, std::uint64_t(o.times_from), std::int64_t(o.frames_backed));
    {
      std::lock_guard lock(json_mutex);
      if (json_db != d) json_cache.clear(), json_db = d;
      if (const auto it = json_cache.find(key); it != json_cache.end()) return it->second;
    }
    const auto t0 = std::chrono::steady_clock::now();
    auto text = std::make_shared<const std::string>(database_json(*d, o).dump());
    log("database.json built (" + std::to_string(text->size()) + " bytes, " +
        std::to_string(std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::steady_clock::now() - t0).count()) +
        " ms); later requests get it from the cache until the manifest changes");
    std::lock_guard lock(json_mutex);
    if (json_db == d) {
      if (json_cache.size() >= kJsonCacheEntries) json_cache.clear();
      json_cache.emplace(key, text);
    }
    return text;
  }
  FragmentIndexCache indexes;  // per movie, checked against size + mtime per request
  std::atomic<bool> stopping{false};
  int listen_socket = -1;  // seen when httplib creates it, to widen its backlog

  static HttpLimits limits(const ServerOptions& o) {
    HttpLimits l;
    l.idle_seconds = l.write_seconds = std::max(1, o.timeout_seconds);
    l.head_seconds = 2 * l.idle_seconds;
    return l;
  }

  explicit Impl(ServerOptions o)
      : options(std::move(o)), db_root(options.database), player_root(options.player_dir), http(limits(options)) {
    std::error_code ec;  // stat first: a manifest replaced meanwhile is then re-read on the first request
    manifest_size = fs::file_size(db_root.dir() / store::kManifestFileName, ec);
    manifest_mtime = fs::last_write_time(db_root.dir() / store::kManifestFileName, ec);
    db = std::make_shared<const store::Database>(store::Database::open(db_root.dir()));
    if (!fs::is_regular_file(player_root.dir() / "index.html"))
      throw FileError(player_root.dir().string(), "no index.html: not the web player's directory");
  }

  /// One line, whatever the parts hold: fields a client sent are escaped by escape_for_log where the
  /// line is made; this catches a line break from anywhere else (an error message quoting a file).
  void log(const std::string& line) const {
    if (!options.log) return;
    std::string out = utc_now_iso8601() + " ";
    for (const char c : line) {
      if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) {
        out += escape_for_log(std::string_view(&c, 1));
      } else {
        out += c;
      }
    }
    options.log(out);
  }

  /// The manifest's size and mtime when `db` was opened: database.json re-opens the database only
  /// when they changed (a running simulation's checkpoint), since an open reads and checks the whole
  /// camera table (64 MB, about a second at 10^6 cameras).
  std::uintmax_t manifest_size = 0;
  fs::file_time_type manifest_mtime{};
  std::chrono::steady_clock::time_point reopened{};
  static constexpr std::chrono::seconds kRunningRecheck{2};

  /// Counts the databases opened (reopen()): a packed stream's cached index is valid for one.
  std::uint64_t db_generation = 0;

  /// The database, reopened first when `reopen` and its manifest changed; `generation`, if given,
  /// receives the count of the opened one.
  std::shared_ptr<const store::Database> database(bool reopen, std::uint64_t* generation = nullptr) {
    std::lock_guard lock(db_mutex);
    if (generation) *generation = db_generation;
    if (reopen) {
      std::error_code ec;
      const fs::path manifest = db_root.dir() / store::kManifestFileName;
      const auto size = fs::file_size(manifest, ec);
      const auto mtime = fs::last_write_time(manifest, ec);
      // A running database's status also depends on its writer being alive (store::Database::open).
      // A running database's unchanged manifest is re-read at most every kRunningRecheck seconds, for
      // its writer's liveness: re-reading it at every request cost seconds each on a 255 MB manifest
      // (issue 44), and many clients poll.
      const auto now = std::chrono::steady_clock::now();
      const bool recheck_running = db->status() == store::Status::running && now - reopened >= kRunningRecheck;
      if (ec || size != manifest_size || mtime != manifest_mtime || recheck_running) {
        reopened = now;
        try {
          db = std::make_shared<const store::Database>(store::Database::open(db_root.dir()));
          if (generation) *generation = ++db_generation;
          if (!ec) manifest_size = size, manifest_mtime = mtime;
        } catch (const Error& e) {
          log(std::string("reopen failed, keeping the previous manifest: ") + e.what());
        }
      }
    }
    return db;
  }

  /// Token check for every request; true = go on routing.
  httplib::Server::HandlerResponse authorize(const httplib::Request& req, httplib::Response& res) {
    // httplib calls this once the request line and headers are read, before it reads any body.
    // A refused request closes the connection: a body left unread is then never parsed as the next
    // request (issue 31: 883 MB buffered from an unauthenticated client).
    const auto refuse = [&](int status, const std::string& why, const std::string& message) {
      log(request_line(req) + " " + std::to_string(status) + " refused: " + why);
      send_error(res, status, message);
      res.set_header("Connection", "close");
      return httplib::Server::HandlerResponse::Handled;
    };
    if (!token_ok(req, res))
      return refuse(401, "missing or wrong token",
                    "this server needs a token: open the URL with ?token=... as printed by panoptes serve");
    if (has_body(req))
      return refuse(413, "a request body (" + escape_for_log(req.get_header_value("Content-Length"), 32) + ")",
                    "this server is read-only: requests with a body are refused");
    if (req.method != "GET" && req.method != "HEAD")
      return refuse(405, "method", "this server is read-only: GET and HEAD only");
    return httplib::Server::HandlerResponse::Unhandled;
  }

  bool token_ok(const httplib::Request& req, httplib::Response& res) const {
    const std::string& token = options.token;
    if (token.empty()) return true;
    const std::string query = req.has_param("token") ? req.get_param_value("token") : "";
    if (!query.empty() && same_secret(query, token)) {
      // The browser then sends the cookie with every request of the page (scripts, movies).
      res.set_header("Set-Cookie", "panoptes_token=" + token + "; Path=/; HttpOnly; SameSite=Strict");
      return true;
    }
    const std::string auth = req.get_header_value("Authorization");
    if (auth.rfind("Bearer ", 0) == 0 && same_secret(auth.substr(7), token)) return true;
    return same_secret(cookie_value(req.get_header_value("Cookie"), "panoptes_token"), token);
  }

  /// The frames the movies can hold, when the manifest claims more than the first stream's movie has
  /// bytes (a frame takes at least one): then that movie's fragment index (cached; its work is bounded
  /// by the file's size) says how many it holds. -1 = not contradicted, or no movie to check against
  /// (a missing or unreadable first movie is that stream's damage, not a measure of the others).
  std::int64_t frames_backed(const store::Database& d, std::uint64_t generation) {
    if (d.camera_count() == 0 || d.task_count() == 0 || d.frame_count() == 0) return -1;
    if (d.packed()) {
      // The first stream's fragments as its pack index names them, once per opened manifest.
      std::lock_guard lock(backed_mutex);
      if (backed_generation != generation) {
        backed_generation = generation;
        try {
          backed_frames = d.packed_stream(0, 0).frames();
          backed_frames = backed_frames < d.frame_count() && backed_frames > 0 ? backed_frames : -1;
        } catch (const Error&) {
          backed_frames = -1;  // that stream's damage, not a measure of the others
        }
      }
      return backed_frames;
    }
    const auto movie = db_root.resolve(d.manifest().stream_relative_path(0, 0));
    if (!movie) return -1;
    std::error_code ec;
    const auto bytes = fs::file_size(*movie, ec);
    if (ec || std::uintmax_t(d.frame_count()) <= bytes) return -1;
    try {
      return indexes.frame_count(*movie);
    } catch (const Error&) {
      return -1;
    }
  }

  std::mutex backed_mutex;
  std::uint64_t backed_generation = ~std::uint64_t(0);
  std::int64_t backed_frames = -1;

  /// GET /api/index/C/T.json of a packed database: the stream's ranges of its packs (web/database_json.hpp,
  /// packed_index_json), built once per opened manifest: a request for a stream seen before reads no
  /// file (the packs' index headers are read once per opened database, by store::Database).
  void packed_index(const store::Database& d, std::uint64_t generation, int camera, int task,
                    const httplib::Request& req, httplib::Response& res) {
    const std::string which = "stream camera " + std::to_string(camera) + ", task " + std::to_string(task);
    try {
      const auto text = indexes.json_keyed(std::to_string(camera) + "/" + std::to_string(task), generation, [&] {
        const store::PackedStream ps = d.packed_stream(camera, task);
        if (ps.pieces.size() < 2) throw std::out_of_range("no pack indexes a fragment of " + which);
        nlohmann::json j = packed_index_json(ps, d.dir());
        try {
          const std::vector<int> damaged = d.damaged_frames(camera, task);
          if (!damaged.empty()) j["damaged_frames"] = damaged;
        } catch (const Error&) {
          // Truncated or unreadable here: the browser finds out by itself.
        }
        return j;
      });
      res.set_header("Cache-Control", "no-cache");
      res.set_content(*text, "application/json");
    } catch (const std::out_of_range& e) {
      log(request_line(req) + " 404 " + e.what());
      send_error(res, 404, e.what());
    } catch (const Error& e) {
      log(request_line(req) + " 422 " + which + ": " + e.what());
      send_error(res, 422, which + ": " + e.what());
    }
  }

  void serve_under(const SafeRoot& root, const std::string& relative, const httplib::Request& req,
                   httplib::Response& res) {
    std::string why;
    store::FileHandle file = root.open(relative, &why);
    if (!file) {
      log(request_line(req) + " 404 refused: " + why);
      return send_error(res, 404, "not found");
    }
    send_file(res, std::move(file), content_type(fs::path(relative)), stopping);
  }

  void routes() {
    http.set_pre_routing_handler([this](const httplib::Request& req, httplib::Response& res) { return authorize(req, res); });
    http.Get("/api/database.json", [this](const httplib::Request& req, httplib::Response& res) {
      res.set_header("Cache-Control", "no-cache");
      DatabaseJsonOptions o;
      o.inline_cameras = req.has_param("cameras") && req.get_param_value("cameras") == "inline";
      o.max_times = kTimesPerPage;
      if (req.has_param("times_from")) {
        const std::string from = req.get_param_value("times_from");
        if (from.empty() || from.size() > 10 || from.find_first_not_of("0123456789") != std::string::npos)
          return send_error(res, 400, "times_from=" + escape_for_log(from, 32) + ": expected a frame number");
        o.times_from = std::stoull(from);
      }
      std::uint64_t generation = 0;
      const auto d = database(true, &generation);
      o.frames_backed = frames_backed(*d, generation);
      res.set_content(*cached_database_json(d, o), "application/json");
    });
    // The players' key table as data (docs/web.md), with this database's view mode.
    http.Get("/api/keys.json", [this](const httplib::Request&, httplib::Response& res) {
      res.set_header("Cache-Control", "no-cache");
      const auto d = database(true);
      res.set_content(player::keys_json(&d->manifest()).dump(), "application/json");
    });
    http.Get(R"(/api/index/(\d{1,9})/(\d{1,9})\.json)", [this](const httplib::Request& req, httplib::Response& res) {
      std::uint64_t generation = 0;
      const auto d = database(false, &generation);
      const int camera = std::stoi(req.matches[1]), task = std::stoi(req.matches[2]);
      if (camera >= d->camera_count() || task >= d->task_count())
        return send_error(res, 404, "no stream (" + std::to_string(camera) + ", " + std::to_string(task) + ")");
      if (d->packed()) return packed_index(*d, generation, camera, task, req, res);
      const std::string relative = d->manifest().stream_relative_path(camera, task);
      std::string why;
      const auto file = db_root.resolve(relative, &why);
      if (!file) {
        log(request_line(req) + " 404 " + relative + ": " + why);
        return send_error(res, 404, relative + ": " + why);
      }
      try {
        res.set_header("Cache-Control", "no-cache");
        // Frames that fail the manifest's frame checks (checksum, identity, index, timestamp): the
        // browser decodes by itself, so the index names them, as export-web's does.
        res.set_content(*indexes.json(*file,
                                      [&](nlohmann::json& j) {
                                        try {
                                          const std::vector<int> damaged = d->damaged_frames(camera, task);
                                          if (!damaged.empty()) j["damaged_frames"] = damaged;
                                        } catch (const Error&) {
                                          // Truncated or unreadable here: the browser finds out by itself.
                                        }
                                      }),
                        "application/json");
      } catch (const Error& e) {
        log(request_line(req) + " 422 " + e.what());
        send_error(res, 422, e.what());
      }
    });
    http.Get(R"(/db/(.*))", [this](const httplib::Request& req, httplib::Response& res) {
      serve_under(db_root, req.matches[1], req, res);
    });
    http.Get(R"(/(.*))", [this](const httplib::Request& req, httplib::Response& res) {
      const std::string relative = req.matches[1];
      serve_under(player_root, relative.empty() ? "index.html" : relative, req, res);
    });
    http.set_logger([this](const httplib::Request& req, const httplib::Response& res) {
      std::string line = request_line(req) + " " + std::to_string(res.status);
      if (req.has_header("Range")) line += " " + escape_for_log(req.get_header_value("Range"), 128);
      log(line);
    });
  }
};

Server::Server(ServerOptions options) : impl_(std::make_unique<Impl>(std::move(options))) {
  auto& o = impl_->options;
  auto& http = impl_->http;
  const std::size_t warm = std::size_t(std::max(1, o.threads));
  const std::size_t max = std::max(warm, std::size_t(std::max(1, o.max_connections)));
  http.new_task_queue = [warm, max] { return new ConnectionThreads(warm, max); };
  // Keep-alive, timeouts and request bounds are BoundedHttpServer's (it reads every connection);
  // httplib only writes these two into its Keep-Alive header.
  http.set_keep_alive_max_count(std::size_t(http.limits().max_requests));
  http.set_keep_alive_timeout(http.limits().idle_seconds);
  // Nothing here takes a body (authorize() refuses one unread); should httplib get to one anyway, it
  // keeps none of it.
  http.set_payload_max_length(0);
  impl_->routes();
  // httplib's default sets SO_REUSEPORT, which lets a second server bind the same port and silently
  // take half of the connections; SO_REUSEADDR alone still allows a quick restart.
  int* listen_socket = &impl_->listen_socket;
  http.set_socket_options([listen_socket](socket_t sock) {
    int yes = 1;
    setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
    *listen_socket = sock;
  });
  if (o.port == 0) {
    impl_->port = http.bind_to_any_port(o.bind);
  } else {
    impl_->port = http.bind_to_port(o.bind, o.port) ? o.port : -1;
  }
  if (impl_->port <= 0)
    throw Error("cannot listen on " + o.bind + ":" + std::to_string(o.port) + " (address in use or not available)");
  // httplib listens with a backlog of 5 (compiled into Debian's library); listen() again on the
  // listening socket only changes its backlog.
  if (impl_->listen_socket < 0 || ::listen(impl_->listen_socket, kListenBacklog) != 0)
    throw Error("cannot widen the listen backlog of " + url() + " to " + std::to_string(kListenBacklog) + ": " +
                std::strerror(errno));
}

Server::~Server() { stop(); }

int Server::port() const { return impl_->port; }

std::string Server::url() const {
  const std::string& host = impl_->options.bind;
  const bool v6 = host.find(':') != std::string::npos;
  return "http://" + (v6 ? "[" + host + "]" : host) + ":" + std::to_string(impl_->port) + "/";
}

void Server::run() { impl_->http.listen_after_bind(); }

void Server::stop() {
  impl_->stopping = true;
  impl_->http.cut_connections();
  impl_->http.stop();
}

fs::path find_player_dir() {
  std::vector<fs::path> tried;
  if (const char* env = std::getenv("PANOPTES_WEB_DIR"); env && *env) {
    if (fs::is_regular_file(fs::path(env) / "index.html")) return env;
    tried.push_back(env);
  }
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    const fs::path dir = exe.parent_path().parent_path() / "share" / "panoptes" / "web";
    if (fs::is_regular_file(dir / "index.html")) return dir;
    tried.push_back(dir);
  }
  std::string list;
  for (const auto& t : tried) list += (list.empty() ? "" : ", ") + t.string();
  // The usual cause: a build of the program alone (before issue 44, scripts/demo built no web player).
  throw Error("the web player's files were not found (looked in " + list +
              "); build them with `scripts/setup` (or `cmake --build build --target web_player`), or set "
              "PANOPTES_WEB_DIR to the directory holding index.html");
}

}  // namespace panoptes::web
