// clod view OUTDIR [--port N] [--host ADDR] [--viewer-dir DIR] [--quit-after S]: serves the
// built web viewer (viewer/dist, see docs/viewer.md) at / and OUTDIR at /data/ over a tiny
// static HTTP/1.1 server, prints the URL on stdout, and runs until SIGINT/SIGTERM (exit 0).
//
// The server is deliberately small: GET and HEAD only, one request per connection
// ("Connection: close"), one thread per connection so that a browser's idle speculative
// connections never block the page's real requests, no directory listings, no caching. Every
// request path is percent-decoded, split into segments, and refused (403) if any segment is
// "." or "..", empty in the middle, or holds a NUL or backslash; the file found is then
// canonicalised and must still lie inside its root (symlinks that leave the root are refused).
#include <arpa/inet.h>
#include <netdb.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "clod/error.h"
#include "command.h"

#ifndef CLOD_VIEWER_DIST_DIR
#define CLOD_VIEWER_DIST_DIR "viewer/dist"
#endif

namespace clod::cli {
namespace {

namespace fs = std::filesystem;

struct ViewOptions {
  std::string outDir;
  int port = 8000;
  std::string host = "127.0.0.1";
  std::string viewerDir;
  double quitAfterSeconds = 0.0;
};

// Limits that keep a misbehaving client from tying the server up: request heads are tiny
// (a browser's GET is well under 2 KB), and a client that sends nothing is dropped.
constexpr std::size_t kMaxRequestHeadBytes = 16 * 1024;
constexpr int kClientTimeoutSeconds = 10;
constexpr int kMaxConcurrentConnections = 64;

volatile std::sig_atomic_t gStopRequested = 0;
void requestStop(int) { gStopRequested = 1; }

struct Response {
  int status = 200;
  std::string reason = "OK";
  std::string contentType = "text/plain; charset=utf-8";
  std::string body;
  std::vector<std::pair<std::string, std::string>> extraHeaders;
};

Response errorResponse(int status, std::string reason, const std::string& detail) {
  Response r;
  r.status = status;
  r.reason = std::move(reason);
  r.body = std::to_string(status) + " " + r.reason + ": " + detail + "\n";
  return r;
}

std::string contentTypeFor(const fs::path& path) {
  std::string ext = path.extension().string();
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  static const std::pair<std::string_view, std::string_view> kTypes[] = {
      {".html", "text/html; charset=utf-8"},   {".htm", "text/html; charset=utf-8"},
      {".js", "text/javascript; charset=utf-8"}, {".mjs", "text/javascript; charset=utf-8"},
      {".css", "text/css; charset=utf-8"},     {".json", "application/json"},
      {".map", "application/json"},            {".glb", "model/gltf-binary"},
      {".gltf", "model/gltf+json"},            {".bin", "application/octet-stream"},
      {".csv", "text/csv; charset=utf-8"},     {".txt", "text/plain; charset=utf-8"},
      {".png", "image/png"},                   {".jpg", "image/jpeg"},
      {".svg", "image/svg+xml"},               {".ico", "image/x-icon"},
      {".wasm", "application/wasm"},           {".woff2", "font/woff2"},
  };
  for (const auto& [e, type] : kTypes)
    if (ext == e) return std::string(type);
  return "application/octet-stream";
}

int hexValue(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

// Decodes %XX escapes; nullopt for a malformed escape.
std::optional<std::string> percentDecode(std::string_view in) {
  std::string out;
  out.reserve(in.size());
  for (std::size_t i = 0; i < in.size(); ++i) {
    if (in[i] != '%') {
      out += in[i];
      continue;
    }
    if (i + 2 >= in.size()) return std::nullopt;
    const int hi = hexValue(in[i + 1]), lo = hexValue(in[i + 2]);
    if (hi < 0 || lo < 0) return std::nullopt;
    out += char(hi * 16 + lo);
    i += 2;
  }
  return out;
}

class StaticServer {
public:
  StaticServer(fs::path viewerRoot, fs::path dataRoot)
      : viewerRoot_(fs::canonical(viewerRoot)), dataRoot_(fs::canonical(dataRoot)) {}

  // Builds the response for one request (method + raw request target).
  Response respond(std::string_view method, std::string_view target) const {
    if (method != "GET" && method != "HEAD") {
      Response r = errorResponse(405, "Method Not Allowed", "only GET and HEAD are served");
      r.extraHeaders.emplace_back("Allow", "GET, HEAD");
      return r;
    }
    // Drop the query and fragment: the viewer's "?data=" parameter is read by the page itself.
    const std::string_view pathPart = target.substr(0, target.find_first_of("?#"));
    if (pathPart.empty() || pathPart.front() != '/') return errorResponse(400, "Bad Request", "bad request target");
    const std::optional<std::string> decoded = percentDecode(pathPart);
    if (!decoded) return errorResponse(400, "Bad Request", "malformed percent escape");

    // Split into segments; any "..", ".", empty inner segment, NUL or backslash is refused
    // outright rather than normalised, so no spelling of a path can climb out of a root.
    std::vector<std::string> segments;
    std::size_t start = 1;
    while (start <= decoded->size()) {
      const std::size_t end = std::min(decoded->find('/', start), decoded->size());
      const std::string segment = decoded->substr(start, end - start);
      const bool last = end == decoded->size();
      if (segment == "." || segment == ".." || (segment.empty() && !last) ||
          segment.find('\0') != std::string::npos || segment.find('\\') != std::string::npos)
        return errorResponse(403, "Forbidden", "path leaves the served folders");
      if (!segment.empty()) segments.push_back(segment);
      start = end + 1;
    }

    fs::path root = viewerRoot_;
    std::size_t first = 0;
    if (!segments.empty() && segments[0] == "data") {
      root = dataRoot_;
      first = 1;
    }
    fs::path file = root;
    for (std::size_t i = first; i < segments.size(); ++i) file /= segments[i];
    std::error_code ec;
    if (fs::is_directory(file, ec)) file /= "index.html";
    if (!fs::is_regular_file(file, ec)) return errorResponse(404, "Not Found", std::string(pathPart));
    // A symlink inside a root may still point outside it; serve only what resolves inside.
    const fs::path real = fs::canonical(file, ec);
    if (ec) return errorResponse(404, "Not Found", std::string(pathPart));
    const auto [rootEnd, fileIt] = std::mismatch(root.begin(), root.end(), real.begin(), real.end());
    if (rootEnd != root.end()) return errorResponse(403, "Forbidden", "path leaves the served folders");
    (void)fileIt;

    std::ifstream in(real, std::ios::binary);
    if (!in) return errorResponse(403, "Forbidden", "file is not readable");
    Response r;
    r.contentType = contentTypeFor(real);
    r.body.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    return r;
  }

private:
  fs::path viewerRoot_;
  fs::path dataRoot_;
};

bool sendAll(int fd, const char* data, std::size_t size) {
  while (size > 0) {
    const ssize_t n = ::send(fd, data, size, MSG_NOSIGNAL);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    data += n;
    size -= std::size_t(n);
  }
  return true;
}

void serveConnection(const StaticServer& server, int fd) {
  timeval timeout{kClientTimeoutSeconds, 0};
  ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof timeout);
  ::setsockopt(fd, SOL_SOCKET, SO_SNDTIMEO, &timeout, sizeof timeout);
  std::string head;
  char buffer[4096];
  while (head.find("\r\n\r\n") == std::string::npos && head.find("\n\n") == std::string::npos) {
    if (head.size() > kMaxRequestHeadBytes) break;
    const ssize_t n = ::recv(fd, buffer, sizeof buffer, 0);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {  // closed or timed out before a complete request: nothing to answer
      ::close(fd);
      return;
    }
    head.append(buffer, std::size_t(n));
  }
  Response response;
  std::string method;
  const std::size_t lineEnd = head.find_first_of("\r\n");
  const std::string line = head.substr(0, lineEnd);
  const std::size_t sp1 = line.find(' '), sp2 = line.rfind(' ');
  if (head.size() > kMaxRequestHeadBytes) {
    response = errorResponse(431, "Request Header Fields Too Large", "request head over 16 KB");
  } else if (sp1 == std::string::npos || sp2 == sp1 || line.compare(sp2 + 1, 7, "HTTP/1.") != 0) {
    response = errorResponse(400, "Bad Request", "malformed request line");
  } else {
    method = line.substr(0, sp1);
    response = server.respond(method, std::string_view(line).substr(sp1 + 1, sp2 - sp1 - 1));
  }
  std::string out = "HTTP/1.1 " + std::to_string(response.status) + " " + response.reason + "\r\n";
  out += "Content-Type: " + response.contentType + "\r\n";
  out += "Content-Length: " + std::to_string(response.body.size()) + "\r\n";
  out += "Cache-Control: no-store\r\nX-Content-Type-Options: nosniff\r\nConnection: close\r\n";
  for (const auto& [name, value] : response.extraHeaders) out += name + ": " + value + "\r\n";
  out += "\r\n";
  if (method != "HEAD") out += response.body;
  sendAll(fd, out.data(), out.size());
  ::shutdown(fd, SHUT_WR);
  ::close(fd);
}

// Opens a listening socket on host:port (port 0 = any free port).
int listenOn(const std::string& host, int port, int& boundPort) {
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  hints.ai_flags = AI_PASSIVE;
  addrinfo* found = nullptr;
  const int rc = ::getaddrinfo(host.c_str(), std::to_string(port).c_str(), &hints, &found);
  if (rc != 0)
    throw Error(ErrorCode::kInvalidArgument, "--host '" + host + "': " + ::gai_strerror(rc));
  std::unique_ptr<addrinfo, void (*)(addrinfo*)> guard(found, ::freeaddrinfo);
  std::string lastError = "no address";
  for (addrinfo* a = found; a; a = a->ai_next) {
    const int fd = ::socket(a->ai_family, a->ai_socktype | SOCK_CLOEXEC, a->ai_protocol);
    if (fd < 0) {
      lastError = std::strerror(errno);
      continue;
    }
    const int one = 1;
    ::setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
    if (::bind(fd, a->ai_addr, a->ai_addrlen) == 0 && ::listen(fd, 64) == 0) {
      sockaddr_storage addr{};
      socklen_t len = sizeof addr;
      ::getsockname(fd, reinterpret_cast<sockaddr*>(&addr), &len);
      boundPort = addr.ss_family == AF_INET6 ? ntohs(reinterpret_cast<sockaddr_in6*>(&addr)->sin6_port)
                                             : ntohs(reinterpret_cast<sockaddr_in*>(&addr)->sin_port);
      return fd;
    }
    lastError = std::strerror(errno);
    ::close(fd);
  }
  throw Error(ErrorCode::kInvalidArgument, "cannot listen on " + host + ":" + std::to_string(port) + ": " +
                                               lastError + " (choose another --port, or --port 0 for any free one)");
}

fs::path findViewerDir(const ViewOptions& o) {
  fs::path dir = CLOD_VIEWER_DIST_DIR;
  if (const char* env = std::getenv("CLOD_VIEWER_DIR"); env && *env) dir = env;
  if (!o.viewerDir.empty()) dir = o.viewerDir;
  std::error_code ec;
  if (!fs::is_regular_file(dir / "index.html", ec))
    throw Error(ErrorCode::kFileNotFound,
                "viewer not built: run scripts/build-viewer.sh (no index.html in '" + dir.string() + "')");
  return dir;
}

int runView(const ViewOptions& o) {
  if (o.port < 0 || o.port > 65535)
    throw Error(ErrorCode::kInvalidArgument, "--port " + std::to_string(o.port) + " is outside 0..65535");
  if (!(o.quitAfterSeconds >= 0.0))
    throw Error(ErrorCode::kInvalidArgument, "--quit-after must be >= 0 seconds");
  std::error_code ec;
  if (!fs::is_directory(o.outDir, ec))
    throw Error(ErrorCode::kFileNotFound, "output folder '" + o.outDir + "' does not exist (or is not a folder)");
  if (!fs::is_regular_file(fs::path(o.outDir) / "scene.glb", ec))
    throw Error(ErrorCode::kFileNotFound, "'" + (fs::path(o.outDir) / "scene.glb").string() +
                                              "' not found: write it with clod simulate SCENE -o " + o.outDir +
                                              " --gltf (or clod export)");
  const fs::path viewerDir = findViewerDir(o);
  const auto server = std::make_shared<const StaticServer>(viewerDir, o.outDir);

  int port = 0;
  const int listenFd = listenOn(o.host, o.port, port);
  struct sigaction action {};
  action.sa_handler = requestStop;
  sigemptyset(&action.sa_mask);
  action.sa_flags = 0;  // no SA_RESTART: poll() must wake up with EINTR
  ::sigaction(SIGINT, &action, nullptr);
  ::sigaction(SIGTERM, &action, nullptr);
  std::signal(SIGPIPE, SIG_IGN);

  const std::string hostInUrl = o.host.find(':') != std::string::npos ? "[" + o.host + "]" : o.host;
  std::cout << "clod view: serving " << o.outDir << " at http://" << hostInUrl << ":" << port
            << "/ (viewer from " << viewerDir.string() << "; Ctrl-C stops)" << std::endl;

  const auto startTime = std::chrono::steady_clock::now();
  auto active = std::make_shared<std::atomic<int>>(0);
  while (!gStopRequested) {
    if (o.quitAfterSeconds > 0.0 &&
        std::chrono::duration<double>(std::chrono::steady_clock::now() - startTime).count() >= o.quitAfterSeconds)
      break;
    pollfd p{listenFd, POLLIN, 0};
    const int ready = ::poll(&p, 1, 200);
    if (ready <= 0) continue;  // timeout, or EINTR from a stop signal
    const int fd = ::accept4(listenFd, nullptr, nullptr, SOCK_CLOEXEC);
    if (fd < 0) continue;
    if (active->load() >= kMaxConcurrentConnections) {
      ::close(fd);
      continue;
    }
    ++*active;
    // Detached, sharing ownership of the server and the counter, so a thread still sending
    // when the loop ends touches nothing that has been destroyed.
    std::thread([server, fd, active] {
      serveConnection(*server, fd);
      --*active;
    }).detach();
  }
  ::close(listenFd);
  // Give requests in flight a moment to finish before the process exits.
  for (int i = 0; i < 50 && active->load() > 0; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  std::cout << "clod view: stopped" << std::endl;
  return 0;
}

const CommandRegistration kRegistration("view", [](CLI::App& app) {
  auto options = std::make_shared<ViewOptions>();
  CLI::App* sub = app.add_subcommand(
      "view", "Serve the web viewer for an output folder (scene.glb, layers.json) on a local HTTP server");
  sub->add_option("outdir", options->outDir, "Output folder of clod simulate --gltf or clod export")->required();
  sub->add_option("--port", options->port, "TCP port; 0 picks a free one (printed)")->capture_default_str();
  sub->add_option("--host", options->host, "Address to bind (default loopback only)")->capture_default_str();
  sub->add_option("--viewer-dir", options->viewerDir,
                  "Built viewer folder (default: env CLOD_VIEWER_DIR, else the source tree's viewer/dist)");
  sub->add_option("--quit-after", options->quitAfterSeconds, "Stop after this many seconds (0 = run until Ctrl-C)");
  return [options] { return runView(*options); };
});

}  // namespace
}  // namespace clod::cli
