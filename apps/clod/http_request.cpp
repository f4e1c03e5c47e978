// Request-head parsing and the Host check of `clod view` (http_request.h).
#include "http_request.h"

#include <arpa/inet.h>

#include <algorithm>
#include <cctype>

namespace clod::cli {
namespace {

std::string lowerCase(std::string_view text) {
  std::string out(text);
  for (char& c : out) c = char(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

std::string_view trimmed(std::string_view text) {
  const auto isSpace = [](char c) { return c == ' ' || c == '\t'; };
  while (!text.empty() && isSpace(text.front())) text.remove_prefix(1);
  while (!text.empty() && isSpace(text.back())) text.remove_suffix(1);
  return text;
}

// RFC 9110 token characters: what a method or a header name may consist of.
bool isToken(std::string_view text) {
  static constexpr std::string_view kSpecials = "!#$%&'*+-.^_`|~";
  return !text.empty() && std::all_of(text.begin(), text.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || kSpecials.find(c) != std::string_view::npos;
  });
}

// Splits the head into lines, accepting bare "\n" endings as well as "\r\n".
std::vector<std::string_view> headLines(std::string_view head) {
  std::vector<std::string_view> lines;
  while (!head.empty()) {
    const std::size_t end = head.find('\n');
    std::string_view line = head.substr(0, end);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    if (line.empty()) break;  // the blank line that ends the head
    lines.push_back(line);
    if (end == std::string_view::npos) break;
    head.remove_prefix(end + 1);
  }
  return lines;
}

bool isIpLiteral(const std::string& name) {
  unsigned char address[16];
  if (::inet_pton(AF_INET, name.c_str(), address) == 1) return true;
  if (name.size() > 2 && name.front() == '[' && name.back() == ']')
    return ::inet_pton(AF_INET6, name.substr(1, name.size() - 2).c_str(), address) == 1;
  return false;
}

bool isWildcardAddress(const std::string& host) {
  unsigned char address[16] = {};
  static constexpr unsigned char kZero[16] = {};
  if (::inet_pton(AF_INET, host.c_str(), address) == 1) return std::equal(address, address + 4, kZero);
  if (::inet_pton(AF_INET6, host.c_str(), address) == 1) return std::equal(address, address + 16, kZero);
  return false;
}

}  // namespace

std::vector<std::string_view> HttpRequest::headerValues(std::string_view lowerName) const {
  std::vector<std::string_view> values;
  for (const auto& [name, value] : headers)
    if (name == lowerName) values.push_back(value);
  return values;
}

std::optional<std::size_t> findHeadEnd(std::string_view bytes, std::size_t searchFrom) {
  // Back up so that a terminator split across two reads is still found.
  const std::size_t from = searchFrom > 3 ? searchFrom - 3 : 0;
  const std::size_t crlf = bytes.find("\r\n\r\n", from);
  const std::size_t lf = bytes.find("\n\n", from);
  if (crlf == std::string_view::npos && lf == std::string_view::npos) return std::nullopt;
  return std::min(crlf == std::string_view::npos ? std::string_view::npos : crlf + 4,
                  lf == std::string_view::npos ? std::string_view::npos : lf + 2);
}

std::optional<HttpRequest> parseRequestHead(std::string_view head) {
  const std::vector<std::string_view> lines = headLines(head);
  if (lines.empty()) return std::nullopt;
  const std::string_view line = lines.front();
  const std::size_t sp1 = line.find(' '), sp2 = line.rfind(' ');
  if (sp1 == std::string_view::npos || sp2 == sp1) return std::nullopt;
  HttpRequest request;
  request.method = std::string(line.substr(0, sp1));
  request.target = std::string(line.substr(sp1 + 1, sp2 - sp1 - 1));
  request.version = std::string(line.substr(sp2 + 1));
  if (!isToken(request.method) || request.target.empty() ||
      (request.version != "HTTP/1.0" && request.version != "HTTP/1.1"))
    return std::nullopt;
  for (std::size_t i = 1; i < lines.size(); ++i) {
    const std::size_t colon = lines[i].find(':');
    if (colon == std::string_view::npos || !isToken(lines[i].substr(0, colon))) return std::nullopt;
    request.headers.emplace_back(lowerCase(lines[i].substr(0, colon)),
                                 std::string(trimmed(lines[i].substr(colon + 1))));
  }
  return request;
}

HostPolicy hostPolicyFor(const std::string& boundHost, int port) {
  HostPolicy policy;
  policy.port = port;
  policy.names = {"localhost", "127.0.0.1", "[::1]"};
  const std::string literal = boundHost.find(':') != std::string::npos ? "[" + boundHost + "]" : boundHost;
  policy.names.push_back(lowerCase(literal));
  policy.acceptIpLiterals = isWildcardAddress(boundHost);
  return policy;
}

bool hostIsAllowed(std::string_view hostValue, const HostPolicy& policy) {
  // Split "name[:port]"; an IPv6 name is bracketed, so its own colons are not the port's.
  const std::size_t nameEnd = !hostValue.empty() && hostValue.front() == '['
                                  ? hostValue.find(']') + 1  // npos + 1 == 0: rejected below
                                  : hostValue.find(':');
  if (nameEnd == 0) return false;
  const std::string name = lowerCase(hostValue.substr(0, nameEnd));
  if (nameEnd < hostValue.size()) {
    if (hostValue[nameEnd] != ':' || hostValue.substr(nameEnd + 1) != std::to_string(policy.port)) return false;
  }
  if (std::find(policy.names.begin(), policy.names.end(), name) != policy.names.end()) return true;
  return policy.acceptIpLiterals && isIpLiteral(name);
}

}  // namespace clod::cli
