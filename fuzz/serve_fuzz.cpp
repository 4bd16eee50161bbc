// `panoptes serve`'s request handling (web/server.hpp): the input is sent as it is, over loopback, to
// a server of a small synthetic database (request line, headers, ranges, paths, tokens, bodies,
// pipelined requests), then the sending side is shut and the answer read. Inputs that mention a
// "token" go to a server that requires the token "fuzz-token", the rest to one that requires none.
// Besides crashes and sanitizer reports, a finding is: a byte of the secret beside the database in an
// answer, a log line that holds a line break (a forged line), or no end of the answer within 15 s
// (the server hung on the connection; its own timeout is 2 s).
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <string>
#include <string_view>
#include <thread>

#include "fuzz/fuzz_support.hpp"
#include "store/synthetic.hpp"
#include "web/server.hpp"

namespace {

namespace fs = std::filesystem;
using namespace panoptes;

[[noreturn]] void fail(const std::string& what) {
  std::fprintf(stderr, "serve_fuzz: %s\n", what.c_str());
  std::abort();
}

/// A server running in its own thread for the process's lifetime.
struct Served {
  std::unique_ptr<web::Server> server;
  std::thread thread;
  Served(const fs::path& db, const fs::path& player, const std::string& token) {
    web::ServerOptions o;
    o.database = db;
    o.player_dir = player;
    o.port = 0;
    o.token = token;
    o.threads = 2;
    o.timeout_seconds = 2;
    o.log = [](const std::string& line) {
      if (line.find_first_of("\r\n") != std::string::npos) fail("a log line with a line break: " + line);
    };
    server = std::make_unique<web::Server>(o);
    thread = std::thread([this] { server->run(); });
    thread.detach();  // runs until the process ends
  }
};

const Served& served(bool with_token) {
  static const fs::path dir = [] {
    const fs::path d = fuzz::scratch_dir() / "serve";
    store::SyntheticOptions o;
    o.cameras = 2, o.tasks = 2, o.frames = 3, o.width = 48, o.height = 32, o.overwrite = true, o.threads = 1;
    o.video.gop = 2;
    store::write_synthetic_database(d / "db", o);
    fs::create_directories(d / "player");
    std::ofstream(d / "player" / "index.html") << "<!doctype html><title>player</title>";
    std::ofstream(d / "secret.txt") << "TOP-SECRET-CONTENT";
    fs::create_symlink(d / "secret.txt", d / "db" / "movies" / "secret.mp4");
    fs::create_directory_symlink(d, d / "db" / "movies" / "outside");
    return d;
  }();
  // Never destroyed: their threads serve until the process ends (a destructor at exit would stop a
  // server under a thread still inside it).
  static const Served* open = new Served(dir / "db", dir / "player", "");
  static const Served* closed = new Served(dir / "db", dir / "player", "fuzz-token");
  return with_token ? *closed : *open;
}

/// Sends `request` and reads the answer until the server closes the connection, both at once (a
/// server answering pipelined requests must not wait for a client that is still sending).
std::string exchange(int port, std::string_view request) {
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_NONBLOCK, 0);
  if (fd < 0) fail("socket");
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(std::uint16_t(port));
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0 && errno != EINPROGRESS) fail("connect");
  std::string answer;
  std::size_t sent = 0;
  bool writing = true;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(15);
  for (;;) {
    if (writing && sent == request.size()) {
      ::shutdown(fd, SHUT_WR);
      writing = false;
    }
    pollfd p{fd, short(POLLIN | (writing ? POLLOUT : 0)), 0};
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) fail("no end of the answer within 15 s");
    if (::poll(&p, 1, int(left.count())) < 0) continue;
    if (writing && (p.revents & POLLOUT)) {
      const ssize_t n = ::send(fd, request.data() + sent, request.size() - sent, MSG_NOSIGNAL);
      if (n > 0) sent += std::size_t(n);
      else if (errno != EAGAIN) writing = false;  // the server closed: it refused the rest
    }
    if (p.revents & (POLLIN | POLLHUP | POLLERR)) {
      char buf[16384];
      const ssize_t n = ::recv(fd, buf, sizeof buf, 0);
      if (n == 0 || (n < 0 && errno != EAGAIN)) break;
      if (n > 0 && answer.size() < (std::size_t(1) << 24)) answer.append(buf, std::size_t(n));
    }
  }
  ::close(fd);
  return answer;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view request(reinterpret_cast<const char*>(data), size);
  const auto& s = served(request.find("token") != std::string_view::npos);
  const std::string answer = exchange(s.server->port(), request);
  if (answer.find("TOP-SECRET") != std::string::npos) fail("the secret beside the database was served");
  return 0;
}
