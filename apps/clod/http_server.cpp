// The poll() loop of `clod view` (http_server.h): admitting connections under the limit,
// reading request heads against a deadline, and streaming answers in chunks.
#include "http_server.h"

#include <fcntl.h>
#include <poll.h>
#include <sys/socket.h>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <vector>

namespace clod::cli {

struct HttpServer::Connection {
  UniqueFd socket;
  Clock::time_point acceptedAt;
  Clock::time_point lastProgress;  // of the answer: when a byte was last accepted by the client
  bool answering = false;          // false while the request head is still being read
  bool closed = false;
  std::string head;        // request bytes received so far
  std::vector<char> out;   // answer bytes to send: the head (and a small body), then file chunks
  std::size_t outSent = 0;
  UniqueFd file;
  std::uint64_t fileOffset = 0;
  std::uint64_t fileLeft = 0;
};

namespace {

// Reads and discards what the client sent that we will not read (a request body, the rest of
// an oversized head): closing a socket with unread input makes the kernel send RST, and an RST
// can make the client drop the answer it has not yet read.
void discardPendingInput(int fd) {
  char sink[4096];
  for (int i = 0; i < 16 && ::recv(fd, sink, sizeof sink, MSG_DONTWAIT) > 0; ++i) {
  }
}

// Ends a connection politely: no more output (FIN after what is queued), unread input dropped.
void hangUp(UniqueFd& socket) {
  if (!socket.valid()) return;
  ::shutdown(socket.get(), SHUT_WR);
  discardPendingInput(socket.get());
  socket.reset();
}

// A short error answer sent with one non-blocking send, for a connection we will not serve
// further (over the limit, too slow): if the client is not reading, it simply gets nothing.
void sendFinalAnswer(UniqueFd& socket, HttpResponse response) {
  const std::string text = responseHead(response) + response.body;
  (void)::send(socket.get(), text.data(), text.size(), MSG_NOSIGNAL | MSG_DONTWAIT);
  hangUp(socket);
}

bool wouldBlock(int error) { return error == EAGAIN || error == EWOULDBLOCK; }

}  // namespace

HttpServer::HttpServer(UniqueFd listener, ServerLimits limits, HostPolicy hosts, RequestHandler handler)
    : listener_(std::move(listener)), limits_(limits), hosts_(std::move(hosts)), handler_(std::move(handler)) {
  // Non-blocking, so that accepting never waits: a connection the kernel queued and the client
  // abandoned before accept() must not stall the loop.
  ::fcntl(listener_.get(), F_SETFL, ::fcntl(listener_.get(), F_GETFL) | O_NONBLOCK);
}

HttpServer::~HttpServer() = default;

void HttpServer::run(const std::function<bool()>& shouldStop) {
  bool stopping = false;
  Clock::time_point stopDeadline{};
  std::vector<pollfd> polled;
  for (;;) {
    const Clock::time_point now = Clock::now();
    if (!stopping && shouldStop()) {
      stopping = true;
      stopDeadline = now + std::chrono::seconds(1);
      listener_.reset();
      for (auto& c : connections_)
        if (!c->answering) c->closed = true;
    }
    removeClosed();
    if (stopping && (connections_.empty() || now >= stopDeadline)) break;

    polled.clear();
    for (const auto& c : connections_)
      polled.push_back({c->socket.get(), short(c->answering ? POLLOUT : POLLIN), 0});
    const bool pollListener = listener_.valid() && now >= acceptPausedUntil_;
    if (pollListener) polled.push_back({listener_.get(), POLLIN, 0});

    if (::poll(polled.data(), polled.size(), pollTimeoutMs(now)) > 0) {
      // Only the connections polled: admitting below appends to connections_.
      for (std::size_t i = 0; i < polled.size() - (pollListener ? 1 : 0); ++i) {
        Connection& c = *connections_[i];
        if (polled[i].revents == 0 || c.closed) continue;
        if (c.answering)
          sendSome(c);
        else
          readHead(c);
      }
      if (pollListener && polled.back().revents != 0) acceptPending();
    }
    expireTimeouts(Clock::now());
  }
  connections_.clear();
}

void HttpServer::acceptPending() {
  // Bounded, so that a flood of connections cannot keep the loop from serving the others.
  for (int i = 0; i < 64; ++i) {
    const int fd = ::accept4(listener_.get(), nullptr, nullptr, SOCK_NONBLOCK | SOCK_CLOEXEC);
    if (fd >= 0) {
      admit(UniqueFd(fd));
      continue;
    }
    if (errno == EMFILE || errno == ENFILE || errno == ENOBUFS || errno == ENOMEM) {
      // Out of descriptors or memory: the listener stays readable, so pause it instead of spinning.
      acceptPausedUntil_ = Clock::now() + std::chrono::milliseconds(100);
      return;
    }
    if (wouldBlock(errno)) return;
    // ECONNABORTED, EINTR, a network error on that one connection: try the next.
  }
}

void HttpServer::admit(UniqueFd socket) {
  removeClosed();
  if (connections_.size() >= limits_.maxConnections && !makeRoom()) {
    HttpResponse busy = errorResponse(503, "Service Unavailable", "too many connections; try again");
    busy.extraHeaders.emplace_back("Retry-After", "1");
    sendFinalAnswer(socket, std::move(busy));
    return;
  }
  auto c = std::make_unique<Connection>();
  c->socket = std::move(socket);
  c->acceptedAt = Clock::now();
  Connection& added = *c;
  connections_.push_back(std::move(c));
  readHead(added);  // the request is often there already: answer it before anything can evict it
}

bool HttpServer::makeRoom() {
  Connection* oldest = nullptr;
  for (const auto& c : connections_)
    if (!c->answering && !c->closed && (!oldest || c->acceptedAt < oldest->acceptedAt)) oldest = c.get();
  if (!oldest) return false;
  hangUp(oldest->socket);
  oldest->closed = true;
  removeClosed();
  return true;
}

void HttpServer::readHead(Connection& c) {
  char buffer[4096];
  for (;;) {
    const ssize_t n = ::recv(c.socket.get(), buffer, sizeof buffer, 0);
    if (n == 0 || (n < 0 && errno != EINTR && !wouldBlock(errno))) {
      c.socket.reset();  // the client left (or the connection failed) before asking anything
      c.closed = true;
      return;
    }
    if (n < 0) {
      if (wouldBlock(errno)) return;
      continue;  // EINTR
    }
    const std::size_t searched = c.head.size();
    c.head.append(buffer, std::size_t(n));
    const std::optional<std::size_t> end = findHeadEnd(c.head, searched);
    if (end && *end <= limits_.maxHeadBytes) {
      c.head.resize(*end);
      const std::optional<HttpRequest> request = parseRequestHead(c.head);
      startAnswer(c, answerFor(request), !request || request->method != "HEAD");
      return;
    }
    if (c.head.size() > limits_.maxHeadBytes) {
      startAnswer(c,
                  errorResponse(431, "Request Header Fields Too Large",
                                "request head over " + std::to_string(limits_.maxHeadBytes / 1024) + " KB"),
                  true);
      return;
    }
  }
}

HttpResponse HttpServer::answerFor(const std::optional<HttpRequest>& request) const {
  if (!request) return errorResponse(400, "Bad Request", "malformed request line or header");
  const std::vector<std::string_view> hosts = request->headerValues("host");
  if (hosts.empty() && request->version == "HTTP/1.1")
    return errorResponse(400, "Bad Request", "HTTP/1.1 request without Host");
  if (hosts.size() > 1) return errorResponse(400, "Bad Request", "more than one Host");
  if (hosts.size() == 1 && !hostIsAllowed(hosts.front(), hosts_))
    return errorResponse(403, "Forbidden",
                         "Host '" + std::string(hosts.front()) +
                             "' is not this server's address (refused against DNS rebinding)");
  return handler_(*request);
}

void HttpServer::startAnswer(Connection& c, HttpResponse response, bool withBody) {
  c.answering = true;
  c.lastProgress = Clock::now();
  c.head = std::string();  // the request is answered; free its bytes
  const std::string head = responseHead(response);
  c.out.assign(head.begin(), head.end());
  if (withBody && response.file.valid()) {
    c.file = std::move(response.file);
    c.fileLeft = response.fileSize;
  } else if (withBody) {
    c.out.insert(c.out.end(), response.body.begin(), response.body.end());
  }
  sendSome(c);  // the socket is almost always writable now: save a trip through poll()
}

void HttpServer::sendSome(Connection& c) {
  bool refilled = false;
  for (;;) {
    if (c.outSent == c.out.size()) {
      if (c.fileLeft == 0) {  // all sent
        hangUp(c.socket);
        c.closed = true;
        return;
      }
      // One chunk per turn, so that one fast reader of a big file cannot starve the others.
      if (refilled) return;
      c.out.resize(std::size_t(std::min<std::uint64_t>(limits_.chunkBytes, c.fileLeft)));
      const ssize_t n = ::pread(c.file.get(), c.out.data(), c.out.size(), off_t(c.fileOffset));
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) {  // read error, or the file shrank: the client sees a short body and the close
        c.socket.reset();
        c.closed = true;
        return;
      }
      c.out.resize(std::size_t(n));
      c.outSent = 0;
      c.fileOffset += std::uint64_t(n);
      c.fileLeft -= std::uint64_t(n);
      refilled = true;
    }
    const ssize_t n = ::send(c.socket.get(), c.out.data() + c.outSent, c.out.size() - c.outSent, MSG_NOSIGNAL);
    if (n > 0) {
      c.outSent += std::size_t(n);
      c.lastProgress = Clock::now();
      continue;
    }
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && wouldBlock(errno)) return;
    c.socket.reset();  // the client went away
    c.closed = true;
    return;
  }
}

void HttpServer::expireTimeouts(Clock::time_point now) {
  for (auto& c : connections_) {
    if (c->closed) continue;
    if (!c->answering && now - c->acceptedAt >= limits_.headTimeout) {
      sendFinalAnswer(c->socket, errorResponse(408, "Request Timeout", "no complete request in time"));
      c->closed = true;
    } else if (c->answering && now - c->lastProgress >= limits_.sendStallTimeout) {
      c->socket.reset();  // the client stopped reading
      c->closed = true;
    }
  }
}

void HttpServer::removeClosed() {
  std::erase_if(connections_, [](const std::unique_ptr<Connection>& c) { return c->closed; });
}

int HttpServer::pollTimeoutMs(Clock::time_point now) const {
  Clock::time_point wake = now + std::chrono::milliseconds(200);  // to notice a stop request
  for (const auto& c : connections_)
    wake = std::min(wake, c->answering ? c->lastProgress + limits_.sendStallTimeout
                                       : c->acceptedAt + limits_.headTimeout);
  if (acceptPausedUntil_ > now) wake = std::min(wake, acceptPausedUntil_);
  const auto wait = std::chrono::ceil<std::chrono::milliseconds>(wake - now).count();
  return int(std::max<decltype(wait)>(wait, 0));
}

}  // namespace clod::cli
