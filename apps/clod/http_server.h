#pragma once
// The connection handling of `clod view`: one thread, poll(), non-blocking sockets, so that no
// client -- silent, trickling, or one that stops reading -- can stop another from being served.
//
//  - At most `maxConnections` connections are open. When a new one arrives at the limit, the
//    connection that has waited longest for its request head is dropped to make room (a browser
//    sends its request as soon as it connects; one that has not is idle or hostile). If every
//    open connection is already being answered, the newcomer gets 503 and is closed at once.
//  - A request head must arrive whole within `headTimeout` of the connection (else 408 and
//    close) and fit in `maxHeadBytes` (else 431).
//  - Files are streamed in `chunkBytes` pieces read with pread() into one buffer per connection;
//    a client that accepts no byte for `sendStallTimeout` is dropped.
//  - Host must be one HostPolicy accepts (else 403); HTTP/1.1 without Host: 400.
#include <chrono>
#include <cstddef>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "http_request.h"
#include "http_response.h"
#include "unique_fd.h"

namespace clod::cli {

struct ServerLimits {
  std::size_t maxConnections = 32;
  std::chrono::milliseconds headTimeout{5000};
  std::chrono::milliseconds sendStallTimeout{10000};
  std::size_t maxHeadBytes = 16 * 1024;
  std::size_t chunkBytes = 64 * 1024;
};

/// Answers one well-formed request whose Host passed the check.
using RequestHandler = std::function<HttpResponse(const HttpRequest&)>;

class HttpServer {
public:
  HttpServer(UniqueFd listener, ServerLimits limits, HostPolicy hosts, RequestHandler handler);
  ~HttpServer();

  /// Serves until `shouldStop()` is true (asked at least every 200 ms); then stops accepting,
  /// gives answers in progress up to one second to finish, and closes everything.
  void run(const std::function<bool()>& shouldStop);

private:
  struct Connection;
  using Clock = std::chrono::steady_clock;

  void acceptPending();
  void admit(UniqueFd socket);
  bool makeRoom();
  void readHead(Connection& c);
  void startAnswer(Connection& c, HttpResponse response, bool withBody);
  HttpResponse answerFor(const std::optional<HttpRequest>& request) const;
  void sendSome(Connection& c);
  void expireTimeouts(Clock::time_point now);
  void removeClosed();
  int pollTimeoutMs(Clock::time_point now) const;

  UniqueFd listener_;
  ServerLimits limits_;
  HostPolicy hosts_;
  RequestHandler handler_;
  std::vector<std::unique_ptr<Connection>> connections_;
  Clock::time_point acceptPausedUntil_{};
};

}  // namespace clod::cli
