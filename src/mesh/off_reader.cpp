#include "off_reader.h"

#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <vector>

#include "clod/error.h"
#include "load_limits.h"
#include "polygon_triangulation.h"

namespace clod::detail {

namespace {

// Cursor over the lines of the text; comments and blank lines are skipped.
class LineReader {
public:
  explicit LineReader(std::string_view text) : text_(text) {}

  // Next non-empty line split into tokens; false at the end of the text.
  bool next(std::vector<std::string_view>& tokens) {
    while (pos_ < text_.size()) {
      std::size_t end = text_.find('\n', pos_);
      if (end == std::string_view::npos) end = text_.size();
      std::string_view line = text_.substr(pos_, end - pos_);
      pos_ = end + 1;
      ++lineNumber_;
      if (auto hash = line.find('#'); hash != std::string_view::npos) line = line.substr(0, hash);
      tokens.clear();
      std::size_t i = 0;
      while (i < line.size()) {
        while (i < line.size() && std::isspace(static_cast<unsigned char>(line[i]))) ++i;
        std::size_t j = i;
        while (j < line.size() && !std::isspace(static_cast<unsigned char>(line[j]))) ++j;
        if (j > i) tokens.push_back(line.substr(i, j - i));
        i = j;
      }
      if (!tokens.empty()) return true;
    }
    return false;
  }
  std::size_t lineNumber() const { return lineNumber_; }

private:
  std::string_view text_;
  std::size_t pos_ = 0;
  std::size_t lineNumber_ = 0;
};

bool parseInteger(std::string_view token, long long& value) {
  auto [ptr, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
  return ec == std::errc() && ptr == token.data() + token.size();
}

bool parseReal(std::string_view token, double& value) {
  // strtod accepts "inf" and "nan" (validation reports them as non-finite, which is the more
  // useful message) and needs a terminated copy.
  if (token.size() > 64) return false;
  char buffer[65];
  token.copy(buffer, token.size());
  buffer[token.size()] = '\0';
  char* end = nullptr;
  value = std::strtod(buffer, &end);
  return end == buffer + token.size();
}

bool isOffKeyword(std::string_view keyword) {
  if (keyword.starts_with("ST")) keyword.remove_prefix(2);
  if (keyword.starts_with("C")) keyword.remove_prefix(1);
  if (keyword.starts_with("N")) keyword.remove_prefix(1);
  return keyword == "OFF";
}

}  // namespace

bool looksLikeOff(std::string_view text) {
  if (text.size() < 3) return false;
  auto lower = [](char c) { return char(std::tolower(static_cast<unsigned char>(c))); };
  return lower(text[0]) == 'o' && lower(text[1]) == 'f' && lower(text[2]) == 'f';
}

OffContent readOff(std::string_view text, const std::string& source, const MeshLoadOptions& limits) {
  LineReader reader(text);
  std::vector<std::string_view> tokens;
  auto fail = [&](ErrorCode code, const std::string& what) -> Error {
    return Error(code, source + ": line " + std::to_string(reader.lineNumber()) + ": " + what);
  };
  auto endedEarly = [&](const std::string& what) -> Error {
    return Error(ErrorCode::kParseError, source + ": the file ends before " + what);
  };

  if (!reader.next(tokens)) throw endedEarly("the OFF counts");
  std::size_t first = 0;
  if (!tokens[0].empty() && std::isalpha(static_cast<unsigned char>(tokens[0][0]))) {
    if (!isOffKeyword(tokens[0])) throw fail(ErrorCode::kParseError, "'" + std::string(tokens[0]) + "' is not an OFF keyword ([ST][C][N]OFF)");
    first = 1;
    if (tokens.size() == 1) {
      if (!reader.next(tokens)) throw endedEarly("the OFF counts");
      first = 0;
    }
  }
  long long vertexCount = 0, faceCount = 0;
  if (tokens.size() < first + 2 || !parseInteger(tokens[first], vertexCount) || !parseInteger(tokens[first + 1], faceCount) ||
      vertexCount < 0 || faceCount < 0)
    throw fail(ErrorCode::kParseError, "expected 'vertexCount faceCount [edgeCount]'");
  const std::string countsLine = source + ": line " + std::to_string(reader.lineNumber());
  enforceLimit(std::uint64_t(vertexCount), limits.maxVertices, "maxVertices", "vertices declared", countsLine);
  // Every vertex and face needs at least a few bytes, so larger counts cannot be honest and
  // would only make us allocate for nothing.
  if (vertexCount > static_cast<long long>(text.size()) || faceCount > static_cast<long long>(text.size()))
    throw fail(ErrorCode::kParseError, "counts " + std::to_string(vertexCount) + " " + std::to_string(faceCount) +
                                           " exceed what a file of " + std::to_string(text.size()) + " bytes can hold");

  OffContent content;
  TriangleMesh& mesh = content.mesh;
  mesh.vertices.reserve(std::size_t(vertexCount));
  for (long long v = 0; v < vertexCount; ++v) {
    if (!reader.next(tokens)) throw endedEarly("vertex " + std::to_string(v) + " of " + std::to_string(vertexCount));
    Vec3 p;
    if (tokens.size() < 3 || !parseReal(tokens[0], p.x()) || !parseReal(tokens[1], p.y()) || !parseReal(tokens[2], p.z()))
      throw fail(ErrorCode::kParseError, "vertex " + std::to_string(v) + ": expected three numbers");
    mesh.vertices.push_back(p);
  }
  std::vector<std::uint32_t> polygon;
  for (long long f = 0; f < faceCount; ++f) {
    if (!reader.next(tokens)) throw endedEarly("face " + std::to_string(f) + " of " + std::to_string(faceCount));
    long long n = 0;
    if (!parseInteger(tokens[0], n) || n < 1)
      throw fail(ErrorCode::kParseError, "face " + std::to_string(f) + ": '" + std::string(tokens[0]) +
                                             "' is not a vertex count >= 1");
    if (static_cast<unsigned long long>(n) > limits.maxPolygonVertices)
      enforceLimit(std::uint64_t(n), limits.maxPolygonVertices, "maxPolygonVertices", "corners in one face",
                   source + ": line " + std::to_string(reader.lineNumber()) + ": face " + std::to_string(f));
    if (static_cast<long long>(tokens.size()) - 1 < n)
      throw fail(ErrorCode::kParseError, "face " + std::to_string(f) + ": " + std::to_string(n) + " vertices announced, " +
                                             std::to_string(tokens.size() - 1) + " values given");
    polygon.clear();
    for (long long k = 1; k <= n; ++k) {
      long long index = 0;
      if (!parseInteger(tokens[std::size_t(k)], index))
        throw fail(ErrorCode::kParseError, "face " + std::to_string(f) + ": '" + std::string(tokens[std::size_t(k)]) +
                                               "' is not a vertex index");
      if (index < 0 || index >= vertexCount)
        throw fail(ErrorCode::kIndexOutOfRange, "face " + std::to_string(f) + ": vertex index " + std::to_string(index) +
                                                    (index < 0 ? " is negative" : " >= vertex count " + std::to_string(vertexCount)));
      polygon.push_back(static_cast<std::uint32_t>(index));
    }
    if (polygon.size() < 3) {
      ++content.ignoredPrimitives;
      continue;
    }
    if (mesh.triangles.size() + (polygon.size() - 2) > limits.maxTriangles)
      enforceLimit(mesh.triangles.size() + (polygon.size() - 2), limits.maxTriangles, "maxTriangles", "triangles so far",
                   source + ": line " + std::to_string(reader.lineNumber()) + ": face " + std::to_string(f));
    if (appendFaceTriangles(mesh.vertices, polygon, mesh.triangles) == PolygonCut::kFanFallback) ++content.fannedPolygons;
  }
  return content;
}

}  // namespace clod::detail
