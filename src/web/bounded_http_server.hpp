#pragma once
// cpp-httplib's server with the connections read by Panoptes, within bounds. Debian's httplib 0.11
// reads a request line or a header line whole before it checks its length (a 200 MB line became
// 209 MB of the server's memory, measured), has no deadline for a request's head (a client sending a
// byte every few seconds holds its connection for ever), and, having answered a request whose body it
// did not read, parses that body as the next request (issue 31: 883 MB from a client without the
// token). Here each connection's request head is read by this class, bounded in bytes, header lines
// and time, and handed to httplib's own request processing (routing, ranges, handlers) as a stream
// that holds that head only: httplib never reads from the socket itself, so it never reads a body.
#include <httplib.h>

#include <atomic>
#include <cstddef>

namespace panoptes::web {

/// What a client may send and how slowly.
struct HttpLimits {
  std::size_t max_request_line = 8192;  ///< bytes of "GET /path HTTP/1.1" (longer: 414)
  std::size_t max_head = 16384;         ///< bytes of request line and headers together (more: 431)
  std::size_t max_header_lines = 100;   ///< header lines (more: 431)
  int head_seconds = 10;   ///< a head must arrive whole within this from its first byte (else 408)
  int idle_seconds = 5;    ///< a kept-alive connection idle this long between requests is closed
  int write_seconds = 5;   ///< a client that reads nothing of an answer this long is dropped
  int max_requests = 1000; ///< requests on one connection before it is closed
};

/// An httplib::Server whose connections are read as described above. Routes, handlers and options are
/// httplib's; a request that announces a body (Content-Length other than 0, Transfer-Encoding) closes
/// its connection once answered (the pre-routing handler is expected to refuse it), without its body
/// being read beyond what arrived with the head.
class BoundedHttpServer : public httplib::Server {
 public:
  explicit BoundedHttpServer(HttpLimits limits = {});
  /// Makes every connection end at its next read or write (within 100 ms when waiting), so that the
  /// listen loop's shutdown does not wait for idle or slow clients; call it before stop().
  void cut_connections() { cutting_ = true; }
  const HttpLimits& limits() const { return limits_; }

 private:
  bool process_and_close_socket(socket_t sock) override;

  HttpLimits limits_;
  std::atomic<bool> cutting_{false};
};

}  // namespace panoptes::web
