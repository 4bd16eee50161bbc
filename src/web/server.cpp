#include "web/server.hpp"

#include <httplib.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>

#include <chrono>
#include <cstdio>
#include <ctime>
#include <mutex>
#include <regex>

#include "core/error.hpp"
#include "store/database.hpp"
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

std::string utc_now() {
  const std::time_t t = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
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

void send_error(httplib::Response& res, int status, const std::string& message) {
  res.status = status;
  res.set_content(nlohmann::json{{"error", message}}.dump(), "application/json");
}

/// Serves an opened file whole or, with a Range header, the asked bytes (httplib answers 206 / 416).
/// Reads go through the descriptor opened by SafeRoot::open (pread: no shared offset, no re-open).
void send_file(httplib::Response& res, store::FileHandle file, const std::string& type) {
  struct stat st{};
  if (::fstat(file.get(), &st) != 0) return send_error(res, 404, "cannot read the file");
  const auto size = std::size_t(st.st_size);
  res.set_header("Cache-Control", "no-cache");
  res.set_header("Accept-Ranges", "bytes");
  if (size == 0) return res.set_content("", type);
  auto fd = std::make_shared<store::FileHandle>(std::move(file));
  res.set_content_provider(size, type, [fd](std::size_t offset, std::size_t length, httplib::DataSink& sink) {
    char buf[64 * 1024];
    while (length > 0) {
      const ssize_t got = ::pread(fd->get(), buf, std::min(length, sizeof buf), off_t(offset));
      if (got < 0 && errno == EINTR) continue;
      if (got <= 0 || !sink.write(buf, std::size_t(got))) return false;
      offset += std::size_t(got);
      length -= std::size_t(got);
    }
    return true;
  });
}

}  // namespace

struct Server::Impl {
  ServerOptions options;
  SafeRoot db_root, player_root;
  httplib::Server http;
  int port = 0;
  std::mutex db_mutex;
  std::shared_ptr<const store::Database> db;
  FragmentIndexCache indexes;  // per movie, checked against size + mtime per request

  explicit Impl(ServerOptions o)
      : options(std::move(o)), db_root(options.database), player_root(options.player_dir) {
    std::error_code ec;  // stat first: a manifest replaced meanwhile is then re-read on the first request
    manifest_size = fs::file_size(db_root.dir() / store::kManifestFileName, ec);
    manifest_mtime = fs::last_write_time(db_root.dir() / store::kManifestFileName, ec);
    db = std::make_shared<const store::Database>(store::Database::open(db_root.dir()));
    if (!fs::is_regular_file(player_root.dir() / "index.html"))
      throw FileError(player_root.dir().string(), "no index.html: not the web player's directory");
  }

  void log(const std::string& line) const {
    if (options.log) options.log(utc_now() + " " + line);
  }

  /// The manifest's size and mtime when `db` was opened: database.json re-opens the database only
  /// when they changed (a running simulation's checkpoint), since an open reads and checks the whole
  /// camera table (64 MB, about a second at 10^6 cameras).
  std::uintmax_t manifest_size = 0;
  fs::file_time_type manifest_mtime{};

  std::shared_ptr<const store::Database> database(bool reopen) {
    std::lock_guard lock(db_mutex);
    if (reopen) {
      std::error_code ec;
      const fs::path manifest = db_root.dir() / store::kManifestFileName;
      const auto size = fs::file_size(manifest, ec);
      const auto mtime = fs::last_write_time(manifest, ec);
      // A running database's status also depends on its writer being alive (store::Database::open):
      // re-read it every time while it says running.
      if (ec || size != manifest_size || mtime != manifest_mtime || db->status() == store::Status::running) {
        try {
          db = std::make_shared<const store::Database>(store::Database::open(db_root.dir()));
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
    const std::string& token = options.token;
    if (token.empty()) return httplib::Server::HandlerResponse::Unhandled;
    const std::string query = req.has_param("token") ? req.get_param_value("token") : "";
    if (!query.empty() && same_secret(query, token)) {
      // The browser then sends the cookie with every request of the page (scripts, movies).
      res.set_header("Set-Cookie", "panoptes_token=" + token + "; Path=/; HttpOnly; SameSite=Strict");
      return httplib::Server::HandlerResponse::Unhandled;
    }
    const std::string auth = req.get_header_value("Authorization");
    if (auth.rfind("Bearer ", 0) == 0 && same_secret(auth.substr(7), token))
      return httplib::Server::HandlerResponse::Unhandled;
    if (same_secret(cookie_value(req.get_header_value("Cookie"), "panoptes_token"), token))
      return httplib::Server::HandlerResponse::Unhandled;
    log(req.remote_addr + " " + req.method + " " + req.path + " 401 refused: missing or wrong token");
    send_error(res, 401, "this server needs a token: open the URL with ?token=... as printed by panoptes serve");
    return httplib::Server::HandlerResponse::Handled;
  }

  void serve_under(const SafeRoot& root, const std::string& relative, const httplib::Request& req,
                   httplib::Response& res) {
    std::string why;
    store::FileHandle file = root.open(relative, &why);
    if (!file) {
      log(req.remote_addr + " " + req.method + " " + req.path + " 404 refused: " + why);
      return send_error(res, 404, "not found");
    }
    send_file(res, std::move(file), content_type(fs::path(relative)));
  }

  void routes() {
    http.set_pre_routing_handler([this](const httplib::Request& req, httplib::Response& res) { return authorize(req, res); });
    http.Get("/api/database.json", [this](const httplib::Request& req, httplib::Response& res) {
      res.set_header("Cache-Control", "no-cache");
      const bool inline_cameras = req.has_param("cameras") && req.get_param_value("cameras") == "inline";
      res.set_content(database_json(*database(true), inline_cameras).dump(), "application/json");
    });
    http.Get(R"(/api/index/(\d{1,9})/(\d{1,9})\.json)", [this](const httplib::Request& req, httplib::Response& res) {
      const auto d = database(false);
      const int camera = std::stoi(req.matches[1]), task = std::stoi(req.matches[2]);
      if (camera >= d->camera_count() || task >= d->task_count())
        return send_error(res, 404, "no stream (" + std::to_string(camera) + ", " + std::to_string(task) + ")");
      const std::string relative = d->manifest().stream_relative_path(camera, task);
      std::string why;
      const auto file = db_root.resolve(relative, &why);
      if (!file) {
        log(req.remote_addr + " GET " + req.path + " 404 " + relative + ": " + why);
        return send_error(res, 404, relative + ": " + why);
      }
      try {
        res.set_header("Cache-Control", "no-cache");
        res.set_content(*indexes.json(*file), "application/json");
      } catch (const Error& e) {
        log(req.remote_addr + " GET " + req.path + " 422 " + e.what());
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
      std::string line = req.remote_addr + " " + req.method + " " + req.path + " " + std::to_string(res.status);
      if (req.has_header("Range")) line += " " + req.get_header_value("Range");
      log(line);
    });
  }
};

Server::Server(ServerOptions options) : impl_(std::make_unique<Impl>(std::move(options))) {
  auto& o = impl_->options;
  const std::size_t threads = std::size_t(std::max(1, o.threads));
  impl_->http.new_task_queue = [threads] { return new httplib::ThreadPool(threads); };
  // A player makes hundreds of small range requests on its (at most 6) connections: keep them open
  // instead of httplib's default of closing a connection after 5 requests.
  impl_->http.set_keep_alive_max_count(1000);
  impl_->routes();
  // httplib's default sets SO_REUSEPORT, which lets a second server bind the same port and silently
  // take half of the connections; SO_REUSEADDR alone still allows a quick restart.
  impl_->http.set_socket_options([](socket_t sock) {
    int yes = 1;
    setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
  });
  if (o.port == 0) {
    impl_->port = impl_->http.bind_to_any_port(o.bind);
  } else {
    impl_->port = impl_->http.bind_to_port(o.bind, o.port) ? o.port : -1;
  }
  if (impl_->port <= 0)
    throw Error("cannot listen on " + o.bind + ":" + std::to_string(o.port) + " (address in use or not available)");
}

Server::~Server() { stop(); }

int Server::port() const { return impl_->port; }

std::string Server::url() const {
  const std::string& host = impl_->options.bind;
  const bool v6 = host.find(':') != std::string::npos;
  return "http://" + (v6 ? "[" + host + "]" : host) + ":" + std::to_string(impl_->port) + "/";
}

void Server::run() { impl_->http.listen_after_bind(); }

void Server::stop() { impl_->http.stop(); }

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
  throw Error("the web player's files were not found (looked in " + list +
              "); set PANOPTES_WEB_DIR to the directory holding index.html");
}

}  // namespace panoptes::web
