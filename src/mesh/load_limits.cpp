#include "load_limits.h"

#include <algorithm>
#include <charconv>

#include "clod/error.h"
#include "text_index_check.h"

namespace clod::detail {

namespace {

bool isBlank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v'; }

// Calls f(lineNumber, line) for each line (without its '\n').
template <class F>
void forEachLine(std::string_view text, F&& f) {
  std::size_t lineNumber = 0, pos = 0;
  while (pos < text.size()) {
    std::size_t end = text.find('\n', pos);
    if (end == std::string_view::npos) end = text.size();
    if (!f(++lineNumber, text.substr(pos, end - pos))) return;
    pos = end + 1;
  }
}

// The first token of a line and the number of tokens after it, up to a '#' comment.
struct LineShape {
  std::string_view keyword;
  std::uint64_t arguments = 0;
};

LineShape shapeOf(std::string_view line) {
  if (auto hash = line.find('#'); hash != std::string_view::npos) line = line.substr(0, hash);
  LineShape shape;
  std::size_t i = 0;
  bool first = true;
  while (i < line.size()) {
    while (i < line.size() && isBlank(line[i])) ++i;
    const std::size_t start = i;
    while (i < line.size() && !isBlank(line[i])) ++i;
    if (i == start) break;
    if (first) shape.keyword = line.substr(start, i - start), first = false;
    else ++shape.arguments;
  }
  return shape;
}

std::string lineLabel(const std::string& source, std::size_t lineNumber) {
  return source + ": line " + std::to_string(lineNumber);
}

// OBJ: `v` lines are vertices; an `f` line of n corners is a polygon of n - 2 triangles and,
// once imported, n vertices.
void checkObjCounts(std::string_view text, const std::string& source, const MeshLoadOptions& options) {
  std::uint64_t vertices = 0, corners = 0, triangles = 0;
  forEachLine(text, [&](std::size_t lineNumber, std::string_view line) {
    const LineShape shape = shapeOf(line);
    // The labels are built only for the error: this runs once per line of big files.
    if (shape.keyword == "v" && ++vertices > options.maxVertices) {
      enforceLimit(vertices, options.maxVertices, "maxVertices", "vertices ('v' lines) so far",
                   lineLabel(source, lineNumber));
    } else if (shape.keyword == "f" && shape.arguments >= 3) {
      corners += shape.arguments;
      triangles += shape.arguments - 2;
      if (corners > options.maxVertices)  // Assimp's OBJ reader makes a vertex of every corner
        enforceLimit(corners, options.maxVertices, "maxVertices", "face corners so far (a vertex each once imported)",
                     lineLabel(source, lineNumber));
      if (shape.arguments > options.maxPolygonVertices)
        enforceLimit(shape.arguments, options.maxPolygonVertices, "maxPolygonVertices", "corners in one face",
                     lineLabel(source, lineNumber));
      if (triangles > options.maxTriangles)
        enforceLimit(triangles, options.maxTriangles, "maxTriangles", "triangles so far", lineLabel(source, lineNumber));
    }
    return true;
  });
}

// PLY: "element vertex N" and "element face N" in the header (up to end_header, whose presence
// findPlyHeaderProblem has checked).
void checkPlyCounts(std::string_view text, const std::string& source, const MeshLoadOptions& options) {
  forEachLine(text, [&](std::size_t lineNumber, std::string_view line) {
    const LineShape shape = shapeOf(line);
    if (shape.keyword == "end_header") return false;
    if (shape.keyword != "element" || shape.arguments != 2) return true;
    // The two arguments: the element's name and its count.
    std::size_t i = line.find("element") + 7;
    while (i < line.size() && isBlank(line[i])) ++i;
    std::size_t j = i;
    while (j < line.size() && !isBlank(line[j])) ++j;
    const std::string_view name = line.substr(i, j - i);
    while (j < line.size() && isBlank(line[j])) ++j;
    std::size_t k = j;
    while (k < line.size() && !isBlank(line[k]) && line[k] != '#') ++k;
    std::uint64_t count = 0;
    const auto [end, ec] = std::from_chars(line.data() + j, line.data() + k, count);
    if (ec != std::errc() || end != line.data() + k) return true;  // Assimp judges malformed headers
    const std::string where = lineLabel(source, lineNumber);
    if (name == "vertex") enforceLimit(count, options.maxVertices, "maxVertices", "vertices declared", where);
    else if (name == "face") enforceLimit(count, options.maxTriangles, "maxTriangles", "faces declared", where);
    else return true;
    // Every vertex (3 coordinates) and face (a list) takes at least one byte in any encoding.
    if (count > text.size())
      throw Error(ErrorCode::kParseError, where + ": " + std::to_string(count) + " " + std::string(name) +
                                              " elements declared, more than a file of " + std::to_string(text.size()) +
                                              " bytes can hold");
    return true;
  });
}

// The command-line flag (separator '-') or scene key ('_') of a MeshLoadOptions limit:
// maxPolygonVertices -> max-polygon-vertices / max_polygon_vertices.
std::string flagName(std::string_view option, char separator) {
  std::string flag;
  for (char c : option) {
    if (c >= 'A' && c <= 'Z') {
      flag += separator;
      flag += static_cast<char>(c - 'A' + 'a');
    } else {
      flag += c;
    }
  }
  return flag;
}

}  // namespace

void enforceLimit(std::uint64_t count, std::uint64_t limit, std::string_view option, std::string_view what,
                  const std::string& where) {
  if (count <= limit) return;
  throw Error(ErrorCode::kUnsupportedMesh, where + ": " + std::to_string(count) + " " + std::string(what) +
                                               ", more than MeshLoadOptions::" + std::string(option) + " = " +
                                               std::to_string(limit) + " (raise it to load this file: clod's --" + flagName(option, '-') +
                                               ", a scene's mesh_limits." + flagName(option, '_') + ")");
}

void checkDeclaredCounts(std::string_view text, std::string_view format, const std::string& source,
                         const MeshLoadOptions& options) {
  if (looksLikePly(text)) checkPlyCounts(text, source, options);
  else if (format == "obj") checkObjCounts(text, source, options);
}

}  // namespace clod::detail
