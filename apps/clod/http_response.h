#pragma once
// One answer of `clod view`'s HTTP server: status, headers, and either a small in-memory body
// (error pages) or an open file that the server streams in fixed-size chunks, so that no file is
// ever held in memory whole.
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "unique_fd.h"

namespace clod::cli {

struct HttpResponse {
  int status = 200;
  std::string reason = "OK";
  std::string contentType = "text/plain; charset=utf-8";
  std::string body;        // sent when `file` is not open
  UniqueFd file;           // a regular file, opened read-only; streamed after the head
  std::uint64_t fileSize = 0;  // Content-Length when `file` is open (from fstat, not a read)
  std::vector<std::pair<std::string, std::string>> extraHeaders;
};

/// A plain-text error page: "STATUS REASON: detail".
HttpResponse errorResponse(int status, std::string reason, const std::string& detail);

/// The status line and headers (ending with the blank line) of `response`; one request per
/// connection, so always "Connection: close".
std::string responseHead(const HttpResponse& response);

}  // namespace clod::cli
