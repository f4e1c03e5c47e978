#pragma once
// The head of one HTTP/1.x request as `clod view` reads it, and the Host-header check that keeps
// a web page on another site from reaching the server through DNS rebinding (a name of the
// attacker's that resolves to 127.0.0.1 still arrives with the attacker's name in Host).
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace clod::cli {

struct HttpRequest {
  std::string method;
  std::string target;   // the raw request target, e.g. "/data/scene.glb?x=1"
  std::string version;  // "HTTP/1.0" or "HTTP/1.1"
  std::vector<std::pair<std::string, std::string>> headers;  // names lower-cased, values trimmed

  /// Every value of header `lowerName`, in order.
  std::vector<std::string_view> headerValues(std::string_view lowerName) const;
};

/// Where the request head (request line + headers) ends in `bytes`, just past its blank line;
/// nullopt while it is incomplete. `searchFrom` skips bytes already searched.
std::optional<std::size_t> findHeadEnd(std::string_view bytes, std::size_t searchFrom = 0);

/// Parses a complete request head; nullopt if the request line or a header line is malformed
/// or the version is not HTTP/1.x.
std::optional<HttpRequest> parseRequestHead(std::string_view head);

/// The Host values the server answers to: the loopback names, the address it is bound to, each
/// with or without its port. Bound to a wildcard address (0.0.0.0, ::) it also takes any IP
/// literal, which is what another machine must use then and which no DNS answer can rebind.
struct HostPolicy {
  std::vector<std::string> names;  // lower-case, IPv6 in brackets: "localhost", "[::1]", ...
  int port = 0;
  bool acceptIpLiterals = false;
};

/// The policy for a server bound to `boundHost` (the --host value) on `port`.
HostPolicy hostPolicyFor(const std::string& boundHost, int port);

/// True if a Host header value is one `policy` accepts.
bool hostIsAllowed(std::string_view hostValue, const HostPolicy& policy);

}  // namespace clod::cli
