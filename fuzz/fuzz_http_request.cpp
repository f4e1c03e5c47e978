// libFuzzer target for the request-head reader of `clod view` (apps/clod/http_request.h): the
// bytes a client sends. Any input must give a head end within the bytes or none, a parsed head
// that keeps the parser's promises or nullopt, and a yes/no from the Host check under each kind of
// bound address; never a crash, a sanitizer report or an exception.
#include <cctype>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "http_request.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  // The first byte is where a previous read ended (findHeadEnd's searchFrom), the rest the bytes.
  const std::size_t searchFrom = data[0];
  const std::string_view bytes(reinterpret_cast<const char*>(data + 1), size - 1);
  const auto end = clod::cli::findHeadEnd(bytes, searchFrom);
  if (end && (*end > bytes.size() || *end < 2)) std::abort();
  const std::string_view head = end ? bytes.substr(0, *end) : bytes;
  const auto request = clod::cli::parseRequestHead(head);
  if (!request) return 0;
  if (request->method.empty() || request->target.empty()) std::abort();
  if (request->version != "HTTP/1.0" && request->version != "HTTP/1.1") std::abort();
  static const clod::cli::HostPolicy policies[] = {clod::cli::hostPolicyFor("127.0.0.1", 8080),
                                                   clod::cli::hostPolicyFor("0.0.0.0", 80),
                                                   clod::cli::hostPolicyFor("::", 1)};
  for (const auto& [name, value] : request->headers) {
    for (char c : name)
      if (std::isupper(static_cast<unsigned char>(c))) std::abort();  // names come lower-cased
    for (const auto& policy : policies) (void)clod::cli::hostIsAllowed(value, policy);
  }
  for (std::string_view host : request->headerValues("host"))
    for (const auto& policy : policies) (void)clod::cli::hostIsAllowed(host, policy);
  return 0;
}
