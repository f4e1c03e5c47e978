// clod view OUTDIR [--port N] [--host ADDR] [--viewer-dir DIR] [--quit-after S]
//                  [--max-connections N] [--header-timeout S] [--send-timeout S]:
// serves the built web viewer (viewer/dist, see docs/viewer.md) at / and OUTDIR at /data/ over a
// tiny static HTTP/1.1 server, prints the URL on stdout, and runs until SIGINT/SIGTERM (exit 0).
//
// The server is deliberately small: GET and HEAD only, one request per connection
// ("Connection: close"), no directory listings, no caching. Which paths are served:
// static_site.h. How connections are handled so that hostile clients cannot lock others out
// (connection limit, deadlines, streaming, the Host check): http_server.h.
#include <arpa/inet.h>
#include <netdb.h>
#include <netinet/in.h>
#include <sys/socket.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <memory>
#include <string>

#include "clod/error.h"
#include "command.h"
#include "http_server.h"
#include "static_site.h"

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
  int maxConnections = 32;
  double headerTimeoutSeconds = 5.0;
  double sendTimeoutSeconds = 10.0;
};

volatile std::sig_atomic_t gStopRequested = 0;
void requestStop(int) { gStopRequested = 1; }

// Opens a listening socket on host:port (port 0 = any free port).
UniqueFd listenOn(const std::string& host, int port, int& boundPort) {
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
    UniqueFd fd(::socket(a->ai_family, a->ai_socktype | SOCK_CLOEXEC, a->ai_protocol));
    if (!fd.valid()) {
      lastError = std::strerror(errno);
      continue;
    }
    const int one = 1;
    ::setsockopt(fd.get(), SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
    if (::bind(fd.get(), a->ai_addr, a->ai_addrlen) == 0 && ::listen(fd.get(), SOMAXCONN) == 0) {
      sockaddr_storage addr{};
      socklen_t len = sizeof addr;
      ::getsockname(fd.get(), reinterpret_cast<sockaddr*>(&addr), &len);
      boundPort = addr.ss_family == AF_INET6 ? ntohs(reinterpret_cast<sockaddr_in6*>(&addr)->sin6_port)
                                             : ntohs(reinterpret_cast<sockaddr_in*>(&addr)->sin_port);
      return fd;
    }
    lastError = std::strerror(errno);
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

// Range checks of the numeric options (bad usage: exit 2).
void checkOptions(const ViewOptions& o) {
  if (o.port < 0 || o.port > 65535)
    throw Error(ErrorCode::kInvalidArgument, "--port " + std::to_string(o.port) + " is outside 0..65535");
  if (!(o.quitAfterSeconds >= 0.0))
    throw Error(ErrorCode::kInvalidArgument, "--quit-after must be >= 0 seconds");
  // Each connection holds a socket and perhaps an open file; the ceiling stays far below the
  // usual 1,024-descriptor limit.
  if (o.maxConnections < 1 || o.maxConnections > 512)
    throw Error(ErrorCode::kInvalidArgument,
                "--max-connections " + std::to_string(o.maxConnections) + " is outside 1..512");
  if (!(o.headerTimeoutSeconds > 0.0 && o.headerTimeoutSeconds <= 3600.0))
    throw Error(ErrorCode::kInvalidArgument, "--header-timeout must be in (0, 3600] seconds");
  if (!(o.sendTimeoutSeconds > 0.0 && o.sendTimeoutSeconds <= 3600.0))
    throw Error(ErrorCode::kInvalidArgument, "--send-timeout must be in (0, 3600] seconds");
}

ServerLimits limitsFrom(const ViewOptions& o) {
  const auto millis = [](double seconds) { return std::chrono::milliseconds(std::llround(seconds * 1000.0)); };
  ServerLimits limits;
  limits.maxConnections = std::size_t(o.maxConnections);
  limits.headTimeout = std::max(millis(o.headerTimeoutSeconds), std::chrono::milliseconds(1));
  limits.sendStallTimeout = std::max(millis(o.sendTimeoutSeconds), std::chrono::milliseconds(1));
  return limits;
}

int runView(const ViewOptions& o) {
  checkOptions(o);
  std::error_code ec;
  if (!fs::is_directory(o.outDir, ec))
    throw Error(ErrorCode::kFileNotFound, "output folder '" + o.outDir + "' does not exist (or is not a folder)");
  if (!fs::is_regular_file(fs::path(o.outDir) / "scene.glb", ec))
    throw Error(ErrorCode::kFileNotFound, "'" + (fs::path(o.outDir) / "scene.glb").string() +
                                              "' not found: write it with clod simulate SCENE -o " + o.outDir +
                                              " --gltf (or clod export)");
  const fs::path viewerDir = findViewerDir(o);
  const StaticSite site(viewerDir, o.outDir);

  int port = 0;
  UniqueFd listener = listenOn(o.host, o.port, port);
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

  HttpServer server(std::move(listener), limitsFrom(o), hostPolicyFor(o.host, port),
                    [&site](const HttpRequest& request) { return site.respond(request.method, request.target); });
  const auto startTime = std::chrono::steady_clock::now();
  server.run([&] {
    return gStopRequested != 0 ||
           (o.quitAfterSeconds > 0.0 &&
            std::chrono::duration<double>(std::chrono::steady_clock::now() - startTime).count() >= o.quitAfterSeconds);
  });
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
  sub->add_option("--max-connections", options->maxConnections,
                  "Open connections at most (1..512); at the limit the longest-waiting idle one is dropped, "
                  "else the newcomer gets 503")
      ->capture_default_str();
  sub->add_option("--header-timeout", options->headerTimeoutSeconds,
                  "Seconds a client has to send its whole request head (else 408 and close)")
      ->capture_default_str();
  sub->add_option("--send-timeout", options->sendTimeoutSeconds,
                  "Seconds an answer may make no progress before its client is dropped")
      ->capture_default_str();
  return [options] { return runView(*options); };
});

}  // namespace
}  // namespace clod::cli
