// serve_load --make-db DIR: writes the synthetic database the benchmark serves (2 cameras, 1 task,
// 30 frames of 64 x 48, gop 5).
// serve_load PORT [KEEPALIVE SLOW REQUESTS SECONDS]: the load and slow-client benchmark of
// `panoptes serve` (issue 31), loopback only, bounded in time. While SLOW sockets (default 100) hold
// connections open (each sent half a request line and then one more byte per second: slowloris; one
// the server closes is opened again at once, so SLOW are open all along), KEEPALIVE clients (default
// 200) each make REQUESTS (default 20) range requests on one kept-alive connection, 0.5 s apart (as a
// player does: the connection idles between them), and one plain client makes a fresh connection per
// request (database.json, a fragment index, a whole movie) every 50 ms until they are done. Every
// request must be answered within 5 s; the run stops by itself after SECONDS (default 60) whatever
// the server does. Prints a Markdown table: requests, answered, within 5 s, latency p50 / p99 / max;
// then the slow sockets the server closed (and were reopened), and the load average.
#include <httplib.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "store/synthetic.hpp"

namespace {

using Clock = std::chrono::steady_clock;

int connect_to(int port) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(std::uint16_t(port));
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (fd >= 0 && ::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0) return fd;
  if (fd >= 0) ::close(fd);
  return -1;
}

struct Latencies {
  std::mutex mutex;
  std::vector<double> ms;
  int failed = 0;
  void add(double v) {
    std::lock_guard lock(mutex);
    ms.push_back(v);
  }
  void fail() {
    std::lock_guard lock(mutex);
    ++failed;
  }
};

std::string load_average() {
  std::ifstream in("/proc/loadavg");
  std::string a, b, c;
  in >> a >> b >> c;
  return a + " " + b + " " + c;
}

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, std::size_t(p * double(v.size() - 1) + 0.5))];
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: serve_load PORT [KEEPALIVE SLOW REQUESTS SECONDS] | serve_load --make-db DIR\n");
    return 2;
  }
  if (std::string(argv[1]) == "--make-db" && argc == 3) {
    panoptes::store::SyntheticOptions o;
    o.cameras = 2, o.tasks = 1, o.frames = 30, o.width = 64, o.height = 48, o.threads = 1, o.overwrite = true;
    o.video.gop = 5;
    panoptes::store::write_synthetic_database(argv[2], o);
    return 0;
  }
  const int port = std::stoi(argv[1]);
  const int keepalive = argc > 2 ? std::stoi(argv[2]) : 200;
  const int slow_count = argc > 3 ? std::stoi(argv[3]) : 100;
  const int requests = argc > 4 ? std::stoi(argv[4]) : 20;
  const int seconds = argc > 5 ? std::stoi(argv[5]) : 60;
  const auto deadline = Clock::now() + std::chrono::seconds(seconds);
  const std::string load_before = load_average();

  // What to ask for: the database and the size of movie (0, 0).
  httplib::Client probe("127.0.0.1", port);
  auto db = probe.Get("/api/index/0/0.json");
  if (!db || db->status != 200) {
    std::fprintf(stderr, "serve_load: no fragment index from 127.0.0.1:%d\n", port);
    return 1;
  }

  // Slow sockets: half a request line, then one byte a second until the end of the run.
  std::vector<int> slow;
  for (int i = 0; i < slow_count; ++i)
    if (const int fd = connect_to(port); fd >= 0 && ::send(fd, "GET /db/movies/", 15, MSG_NOSIGNAL) == 15) slow.push_back(fd);
  std::atomic<bool> done{false};
  std::atomic<int> reopened{0};
  std::thread trickle([&] {
    while (!done && Clock::now() < deadline) {
      std::this_thread::sleep_for(std::chrono::seconds(1));
      for (int& fd : slow) {
        char answer[512];
        const bool closed = ::recv(fd, answer, sizeof answer, MSG_DONTWAIT) >= 0;  // an answer (408) or the end
        if (!closed && ::send(fd, "x", 1, MSG_NOSIGNAL | MSG_DONTWAIT) == 1) continue;
        ::close(fd);
        fd = connect_to(port);
        if (fd >= 0) ::send(fd, "GET /db/movies/", 15, MSG_NOSIGNAL);
        ++reopened;
      }
    }
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(300));  // the slow sockets are in before the load

  Latencies keep, plain;
  const auto timed = [&](httplib::Client& c, const std::string& path, const httplib::Headers& h, Latencies& into) {
    const auto t = Clock::now();
    auto res = c.Get(path, h);
    const double ms = std::chrono::duration<double, std::milli>(Clock::now() - t).count();
    if (res && (res->status == 200 || res->status == 206)) into.add(ms);
    else into.fail();
  };
  const auto start = Clock::now();
  std::vector<std::thread> clients;
  for (int k = 0; k < keepalive; ++k)
    clients.emplace_back([&, k] {
      httplib::Client c("127.0.0.1", port);
      c.set_keep_alive(true);
      c.set_connection_timeout(10, 0);
      c.set_read_timeout(10, 0);
      for (int i = 0; i < requests && Clock::now() < deadline; ++i) {
        const int a = (k * 97 + i * 31) % 512;
        timed(c, "/db/movies/c0/t0.mp4", {{"Range", "bytes=" + std::to_string(a) + "-" + std::to_string(a + 255)}}, keep);
        std::this_thread::sleep_for(std::chrono::milliseconds(500));
      }
    });
  std::thread normal([&] {
    const char* paths[] = {"/api/database.json", "/api/index/0/0.json", "/db/movies/c0/t0.mp4"};
    for (int i = 0; !done && Clock::now() < deadline; ++i) {
      httplib::Client c("127.0.0.1", port);
      c.set_connection_timeout(10, 0);
      c.set_read_timeout(10, 0);
      timed(c, paths[i % 3], {}, plain);
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
  });
  for (auto& t : clients) t.join();
  const double load_seconds = std::chrono::duration<double>(Clock::now() - start).count();
  done = true;
  normal.join();
  trickle.join();
  for (int fd : slow) ::close(fd);

  const auto row = [&](const char* who, int clients_n, Latencies& l) {
    const int asked = int(l.ms.size()) + l.failed;
    const auto within = std::count_if(l.ms.begin(), l.ms.end(), [](double v) { return v <= 5000; });
    std::printf("| %s | %d | %d | %zu | %ld | %.1f | %.1f | %.1f |\n", who, clients_n, asked, l.ms.size(), long(within),
                percentile(l.ms, 0.5), percentile(l.ms, 0.99), percentile(l.ms, 1.0));
  };
  std::printf("| clients | connections | requests | answered | within 5 s | p50 ms | p99 ms | max ms |\n");
  std::printf("|---|---|---|---|---|---|---|---|\n");
  row("keep-alive (range requests)", keepalive, keep);
  row("plain (new connection each)", 1, plain);
  std::printf("\nSlow sockets: %d open all along (a byte a second each; %d closed by the server and opened again); "
              "keep-alive phase %.1f s; load average before %s, after %s.\n",
              int(slow.size()), reopened.load(), load_seconds, load_before.c_str(), load_average().c_str());
  const bool ok = keep.failed == 0 && plain.failed == 0 && percentile(keep.ms, 1.0) <= 5000 && percentile(plain.ms, 1.0) <= 5000;
  return ok ? 0 : 1;
}
