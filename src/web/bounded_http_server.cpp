#include "web/bounded_http_server.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <string>
#include <string_view>

namespace panoptes::web {

namespace {

using Clock = std::chrono::steady_clock;
constexpr int kSliceMs = 100;  // longest wait between looks at cut_connections()

std::string address(const sockaddr_storage& a) {
  char text[INET6_ADDRSTRLEN] = "";
  if (a.ss_family == AF_INET)
    inet_ntop(AF_INET, &reinterpret_cast<const sockaddr_in&>(a).sin_addr, text, sizeof text);
  else if (a.ss_family == AF_INET6)
    inet_ntop(AF_INET6, &reinterpret_cast<const sockaddr_in6&>(a).sin6_addr, text, sizeof text);
  return text;
}

int port_of(const sockaddr_storage& a) {
  if (a.ss_family == AF_INET) return ntohs(reinterpret_cast<const sockaddr_in&>(a).sin_port);
  if (a.ss_family == AF_INET6) return ntohs(reinterpret_cast<const sockaddr_in6&>(a).sin6_port);
  return 0;
}

/// The stream httplib processes one request from: reads come from the head already read (and end
/// there), writes go to the socket, each stalled no longer than the write limit.
class HeadStream : public httplib::Stream {
 public:
  HeadStream(int sock, std::string_view head, int write_seconds, const std::atomic<bool>& cutting)
      : sock_(sock), head_(head), write_seconds_(write_seconds), cutting_(cutting) {}

  bool is_readable() const override { return pos_ < head_.size(); }
  bool is_writable() const override {
    pollfd p{sock_, POLLOUT, 0};
    return !cutting_ && ::poll(&p, 1, 0) >= 0 && !(p.revents & (POLLERR | POLLHUP | POLLNVAL));
  }
  ssize_t read(char* ptr, size_t size) override {
    const std::size_t n = std::min(size, head_.size() - pos_);
    std::memcpy(ptr, head_.data() + pos_, n);
    pos_ += n;
    return ssize_t(n);
  }
  ssize_t write(const char* ptr, size_t size) override {
    std::size_t sent = 0;
    auto stalled_since = Clock::now();
    while (sent < size) {
      if (cutting_ || Clock::now() - stalled_since > std::chrono::seconds(write_seconds_)) return -1;
      pollfd p{sock_, POLLOUT, 0};
      const int ready = ::poll(&p, 1, kSliceMs);
      if (ready < 0 && errno != EINTR) return -1;
      if (ready <= 0) continue;
      const ssize_t n = ::send(sock_, ptr + sent, size - sent, MSG_NOSIGNAL | MSG_DONTWAIT);
      if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR)) continue;
      if (n <= 0) return -1;
      sent += std::size_t(n);
      stalled_since = Clock::now();
    }
    return ssize_t(size);
  }
  void get_remote_ip_and_port(std::string& ip, int& port) const override {
    sockaddr_storage a{};
    socklen_t len = sizeof a;
    if (::getpeername(sock_, reinterpret_cast<sockaddr*>(&a), &len) == 0) ip = address(a), port = port_of(a);
  }
  void get_local_ip_and_port(std::string& ip, int& port) const override {
    sockaddr_storage a{};
    socklen_t len = sizeof a;
    if (::getsockname(sock_, reinterpret_cast<sockaddr*>(&a), &len) == 0) ip = address(a), port = port_of(a);
  }
  socket_t socket() const override { return sock_; }

 private:
  int sock_;
  std::string_view head_;
  std::size_t pos_ = 0;
  int write_seconds_;
  const std::atomic<bool>& cutting_;
};

/// How reading a request head ended.
enum class Head { complete, closed, idle, slow, line_too_long, too_big, cut };

bool iequals(std::string_view a, std::string_view b) {
  return a.size() == b.size() &&
         std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) { return std::tolower((unsigned char)x) == std::tolower((unsigned char)y); });
}

/// Does the head announce a body (Content-Length other than 0, or any Transfer-Encoding)?
bool announces_body(std::string_view head) {
  for (std::size_t p = head.find("\r\n"); p != std::string_view::npos && p + 2 < head.size();) {
    const std::size_t start = p + 2, end = head.find("\r\n", start);
    if (end == std::string_view::npos) break;
    const std::string_view line = head.substr(start, end - start);
    const std::size_t colon = line.find(':');
    if (colon != std::string_view::npos) {
      const std::string_view name = line.substr(0, colon);
      std::string_view value = line.substr(colon + 1);
      while (!value.empty() && (value.front() == ' ' || value.front() == '\t')) value.remove_prefix(1);
      while (!value.empty() && (value.back() == ' ' || value.back() == '\t')) value.remove_suffix(1);
      if (iequals(name, "transfer-encoding")) return true;
      if (iequals(name, "content-length") && value.find_first_not_of('0') != std::string_view::npos) return true;
    }
    p = end;
  }
  return false;
}

}  // namespace

BoundedHttpServer::BoundedHttpServer(HttpLimits limits) : limits_(limits) {}


bool BoundedHttpServer::process_and_close_socket(socket_t sock) {
  int yes = 1;
  ::setsockopt(sock, IPPROTO_TCP, TCP_NODELAY, &yes, sizeof yes);
  std::string buffer;  // the head being read, then what came after it (a pipelined request)
  const HttpLimits& l = limits_;

  // Reads until buffer holds a whole head (its length in `head_size`), within the limits.
  const auto read_head = [&](std::size_t& head_size) {
    const auto idle_end = Clock::now() + std::chrono::seconds(l.idle_seconds);
    auto head_end = Clock::time_point::max();
    for (;;) {
      if (!buffer.empty() && head_end == Clock::time_point::max())
        head_end = Clock::now() + std::chrono::seconds(l.head_seconds);
      const std::size_t line_end = buffer.find("\r\n");
      if ((line_end == std::string::npos ? buffer.size() : line_end) > l.max_request_line) return Head::line_too_long;
      if (const std::size_t end = buffer.find("\r\n\r\n"); end != std::string::npos) {
        head_size = end + 4;
        if (head_size > l.max_head) return Head::too_big;
        std::size_t lines = 0;
        for (std::size_t p = buffer.find("\r\n"); p < end; p = buffer.find("\r\n", p + 2)) ++lines;
        return lines > l.max_header_lines ? Head::too_big : Head::complete;
      }
      if (buffer.size() >= l.max_head) return Head::too_big;
      if (cutting_) return Head::cut;
      const auto now = Clock::now();
      if (buffer.empty() ? now >= idle_end : now >= head_end) return buffer.empty() ? Head::idle : Head::slow;
      pollfd p{sock, POLLIN, 0};
      const int ready = ::poll(&p, 1, kSliceMs);
      if (ready < 0 && errno != EINTR) return Head::closed;
      if (ready <= 0) continue;
      char chunk[4096];
      const std::size_t room = std::min(sizeof chunk, l.max_head - buffer.size());
      const ssize_t n = ::recv(sock, chunk, room, MSG_DONTWAIT);
      if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR)) continue;
      if (n <= 0) return Head::closed;
      buffer.append(chunk, std::size_t(n));
    }
  };
  // A refusal written here, before httplib saw the request (there is none it could parse).
  const auto refuse = [&](int status, const char* phrase, const std::string& reason) {
    const std::string body = "{\"error\":\"" + reason + "\"}";
    const std::string answer = "HTTP/1.1 " + std::to_string(status) + " " + phrase +
                               "\r\nContent-Type: application/json\r\nContent-Length: " + std::to_string(body.size()) +
                               "\r\nConnection: close\r\n\r\n" + body;
    HeadStream out(sock, {}, l.write_seconds, cutting_);
    out.write(answer.data(), answer.size());
  };

  bool unread_input = false;
  for (int served = 0; served < l.max_requests; ++served) {
    std::size_t head_size = 0;
    const Head h = read_head(head_size);
    if (h == Head::line_too_long)
      refuse(414, "URI Too Long", "request line longer than " + std::to_string(l.max_request_line) + " bytes");
    if (h == Head::too_big)
      refuse(431, "Request Header Fields Too Large",
             "request head beyond " + std::to_string(l.max_head) + " bytes or " + std::to_string(l.max_header_lines) +
                 " header lines");
    if (h == Head::slow)
      refuse(408, "Request Timeout", "request head not received within " + std::to_string(l.head_seconds) + " s");
    if (h != Head::complete) {
      unread_input = h == Head::line_too_long || h == Head::too_big || h == Head::slow;
      break;
    }
    const std::string_view head(buffer.data(), head_size);
    const bool body = announces_body(head);
    HeadStream stream(sock, head, l.write_seconds, cutting_);
    bool closed = false;
    const bool ok = process_request(stream, served + 1 == l.max_requests, closed, nullptr);
    buffer.erase(0, head_size);
    if (!ok || closed || body || cutting_) {
      unread_input = !cutting_ && (body || !buffer.empty());
      break;
    }
  }
  // Closing a socket with input unread makes the kernel send a reset, which can destroy the answer
  // before the client has read it: end the sending side first and let the client's bytes drain a
  // moment (bounded: 64 kB or 200 ms, never the whole body).
  ::shutdown(sock, SHUT_WR);
  if (unread_input) {
    const auto end = Clock::now() + std::chrono::milliseconds(200);
    std::size_t drained = 0;
    char chunk[4096];
    while (drained < 65536 && Clock::now() < end) {
      pollfd p{sock, POLLIN, 0};
      if (::poll(&p, 1, 20) <= 0) continue;
      const ssize_t n = ::recv(sock, chunk, sizeof chunk, MSG_DONTWAIT);
      if (n <= 0) break;
      drained += std::size_t(n);
    }
  }
  ::close(sock);
  return true;
}

}  // namespace panoptes::web
