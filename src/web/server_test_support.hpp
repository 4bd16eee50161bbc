#pragma once
// What the server tests share: a small database with a player directory and a secret beside them, a
// server running in a thread, and a raw socket client for what httplib's client will not send.
#include <gtest/gtest.h>
#include <httplib.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>

#include "store/database.hpp"
#include "store/manifest.hpp"
#include "store/synthetic.hpp"
#include "store/test_support.hpp"
#include "web/server.hpp"

namespace panoptes::web::testing {

namespace fs = std::filesystem;

inline std::string read_file(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

/// A database, a player directory and a secret file beside them that must never be served.
struct Fixture {
  store::testing::TempDir tmp{"web-server"};
  fs::path db = tmp.path / "db", player = tmp.path / "player", secret = tmp.path / "secret.txt";
  Fixture() {
    store::SyntheticOptions o;
    o.cameras = 3;
    o.tasks = 2;
    o.frames = 5;
    o.width = 64;
    o.height = 48;
    o.video.gop = 2;
    o.threads = 1;
    store::write_synthetic_database(db, o);
    // A preferred playback rate, as the demo records one (the web player plays at it, as the desktop one).
    store::Manifest m = store::read_manifest(db / store::kManifestFileName);
    m.playback_fps = 12.5;
    store::write_manifest_atomic(db / store::kManifestFileName, m);
    fs::create_directories(player);
    std::ofstream(player / "index.html") << "<!doctype html><title>player</title>";
    std::ofstream(secret) << "TOP-SECRET-CONTENT";
    // Links out of the database (a directory and a file) and one that stays inside.
    fs::create_directory_symlink(tmp.path, db / "movies" / "outside");
    fs::create_symlink(secret, db / "movies" / "c0" / "secret.mp4");
    fs::create_symlink(db / "movies" / "c0" / "t0.mp4", db / "movies" / "inside.mp4");
  }
};

/// A stamped synthetic database in the packed layout, written as a simulation writes it: snapshot by
/// snapshot with a checkpoint each, so a stream's fragments lie between the other streams' in its pack.
inline void write_packed_database(const fs::path& dir, int cameras, int tasks, int frames, int width = 64, int height = 48) {
  store::SyntheticOptions o;
  o.cameras = cameras;
  o.tasks = tasks;
  o.frames = frames;
  o.width = width;
  o.height = height;
  o.video.gop = 1;
  const store::Manifest m = store::synthetic_manifest(o);
  store::WriterOptions w;
  w.layout = store::LayoutChoice::packed;
  store::DatabaseWriter writer = store::DatabaseWriter::create(dir, m, w);
  for (int f = 0; f < frames; ++f) {
    for (int c = 0; c < cameras; ++c)
      for (int t = 0; t < tasks; ++t) writer.append(c, t, store::synthetic_frame(c, t, f, width, height));
    writer.checkpoint();
  }
  writer.finalize();
}

/// The bytes [offset, offset + size) of a file.
inline std::string read_range(const fs::path& p, std::uint64_t offset, std::uint64_t size) {
  return read_file(p).substr(std::size_t(offset), std::size_t(size));
}

/// A server on a free port, running in a thread for the test's lifetime.
struct Running {
  Server server;
  std::thread thread;
  explicit Running(ServerOptions o) : server(std::move(o)) {
    thread = std::thread([this] { server.run(); });
    httplib::Client probe("127.0.0.1", server.port());
    for (int i = 0; i < 200 && !probe.Get("/api/database.json"); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ~Running() {
    server.stop();
    thread.join();
  }
};

inline ServerOptions options(const Fixture& f, std::string token = {}) {
  ServerOptions o;
  o.database = f.db;
  o.player_dir = f.player;
  o.port = 0;
  o.token = std::move(token);
  return o;
}

/// A raw TCP connection to the server, for requests a well-behaved client does not send.
class RawClient {
 public:
  explicit RawClient(int port) : fd_(::socket(AF_INET, SOCK_STREAM, 0)) {
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_port = htons(std::uint16_t(port));
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    connected_ = fd_ >= 0 && ::connect(fd_, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0;
  }
  ~RawClient() {
    if (fd_ >= 0) ::close(fd_);
  }
  RawClient(const RawClient&) = delete;
  RawClient& operator=(const RawClient&) = delete;
  bool connected() const { return connected_; }
  /// Sends all of `bytes`; false if the server closed the connection meanwhile.
  bool send(const std::string& bytes) {
    for (std::size_t sent = 0; sent < bytes.size();) {
      const ssize_t n = ::send(fd_, bytes.data() + sent, bytes.size() - sent, MSG_NOSIGNAL);
      if (n <= 0) return false;
      sent += std::size_t(n);
    }
    return true;
  }
  /// What arrives within `timeout` or until the server closes the connection, whichever comes first;
  /// stops early once `until` has been received (when given).
  std::string receive(std::chrono::milliseconds timeout, const std::string& until = {}) {
    std::string got;
    const auto end = std::chrono::steady_clock::now() + timeout;
    for (;;) {
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(end - std::chrono::steady_clock::now());
      if (left.count() <= 0) break;
      pollfd p{fd_, POLLIN, 0};
      if (::poll(&p, 1, int(left.count())) <= 0) break;
      char buf[4096];
      const ssize_t n = ::recv(fd_, buf, sizeof buf, 0);
      if (n <= 0) {
        closed_ = true;
        break;
      }
      got.append(buf, std::size_t(n));
      if (!until.empty() && got.find(until) != std::string::npos) break;
    }
    return got;
  }
  /// Whether receive() saw the server close the connection.
  bool closed() const { return closed_; }

 private:
  int fd_;
  bool connected_ = false, closed_ = false;
};

}  // namespace panoptes::web::testing
