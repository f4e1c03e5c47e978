// Mapping request targets to files of the viewer and output folders (static_site.h).
#include "static_site.h"

#include <fcntl.h>
#include <sys/stat.h>

#include <algorithm>
#include <cctype>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace clod::cli {
namespace {

namespace fs = std::filesystem;

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

// The segments of a decoded absolute path, or nullopt if one of them could climb out of a root.
std::optional<std::vector<std::string>> safeSegments(const std::string& decoded) {
  std::vector<std::string> segments;
  std::size_t start = 1;
  while (start <= decoded.size()) {
    const std::size_t end = std::min(decoded.find('/', start), decoded.size());
    std::string segment = decoded.substr(start, end - start);
    const bool last = end == decoded.size();
    if (segment == "." || segment == ".." || (segment.empty() && !last) ||
        segment.find('\0') != std::string::npos || segment.find('\\') != std::string::npos)
      return std::nullopt;
    if (!segment.empty()) segments.push_back(std::move(segment));
    start = end + 1;
  }
  return segments;
}

bool liesInside(const fs::path& root, const fs::path& real) {
  return std::mismatch(root.begin(), root.end(), real.begin(), real.end()).first == root.end();
}

}  // namespace

StaticSite::StaticSite(const fs::path& viewerRoot, const fs::path& dataRoot)
    : viewerRoot_(fs::canonical(viewerRoot)), dataRoot_(fs::canonical(dataRoot)) {}

HttpResponse StaticSite::respond(std::string_view method, std::string_view target) const {
  if (method != "GET" && method != "HEAD") {
    HttpResponse r = errorResponse(405, "Method Not Allowed", "only GET and HEAD are served");
    r.extraHeaders.emplace_back("Allow", "GET, HEAD");
    return r;
  }
  // Drop the query and fragment: the viewer's "?data=" parameter is read by the page itself.
  const std::string_view pathPart = target.substr(0, target.find_first_of("?#"));
  if (pathPart.empty() || pathPart.front() != '/') return errorResponse(400, "Bad Request", "bad request target");
  const std::optional<std::string> decoded = percentDecode(pathPart);
  if (!decoded) return errorResponse(400, "Bad Request", "malformed percent escape");
  const std::optional<std::vector<std::string>> segments = safeSegments(*decoded);
  if (!segments) return errorResponse(403, "Forbidden", "path leaves the served folders");

  const bool isData = !segments->empty() && segments->front() == "data";
  const fs::path& root = isData ? dataRoot_ : viewerRoot_;
  fs::path file = root;
  for (std::size_t i = isData ? 1 : 0; i < segments->size(); ++i) file /= (*segments)[i];
  std::error_code ec;
  if (fs::is_directory(file, ec)) file /= "index.html";
  if (!fs::is_regular_file(file, ec)) return errorResponse(404, "Not Found", std::string(pathPart));
  // A symlink inside a root may still point outside it; serve only what resolves inside.
  const fs::path real = fs::canonical(file, ec);
  if (ec) return errorResponse(404, "Not Found", std::string(pathPart));
  if (!liesInside(root, real)) return errorResponse(403, "Forbidden", "path leaves the served folders");

  // O_NOFOLLOW and O_NONBLOCK: should the file be swapped for a link or a FIFO after the checks
  // above, open neither follows the link nor waits for a writer; fstat then sees what was opened.
  UniqueFd fd(::open(real.c_str(), O_RDONLY | O_CLOEXEC | O_NOFOLLOW | O_NONBLOCK));
  if (!fd.valid()) return errorResponse(403, "Forbidden", "file is not readable");
  struct stat info {};
  if (::fstat(fd.get(), &info) != 0 || !S_ISREG(info.st_mode))
    return errorResponse(403, "Forbidden", "not a regular file");
  HttpResponse r;
  r.contentType = contentTypeFor(real);
  r.file = std::move(fd);
  r.fileSize = std::uint64_t(info.st_size);
  return r;
}

}  // namespace clod::cli
