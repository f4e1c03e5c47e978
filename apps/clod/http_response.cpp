// Building the head of an HTTP answer (http_response.h).
#include "http_response.h"

namespace clod::cli {

HttpResponse errorResponse(int status, std::string reason, const std::string& detail) {
  HttpResponse r;
  r.status = status;
  r.reason = std::move(reason);
  r.body = std::to_string(status) + " " + r.reason + ": " + detail + "\n";
  return r;
}

std::string responseHead(const HttpResponse& response) {
  const std::uint64_t length = response.file.valid() ? response.fileSize : response.body.size();
  std::string head = "HTTP/1.1 " + std::to_string(response.status) + " " + response.reason + "\r\n";
  head += "Content-Type: " + response.contentType + "\r\n";
  head += "Content-Length: " + std::to_string(length) + "\r\n";
  head += "Cache-Control: no-store\r\nX-Content-Type-Options: nosniff\r\nConnection: close\r\n";
  for (const auto& [name, value] : response.extraHeaders) head += name + ": " + value + "\r\n";
  head += "\r\n";
  return head;
}

}  // namespace clod::cli
