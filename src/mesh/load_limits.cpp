#include "load_limits.h"

#include <algorithm>
#include <charconv>
#include <limits>
#include <vector>

#include "clod/error.h"
#include "text_index_check.h"

namespace clod::detail {

namespace {

bool isBlank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v'; }

// The next token of `s` from `at` -- blanks and line ends separate tokens -- with `at` moved past
// it; empty at the end of `s`.
std::string_view nextToken(std::string_view s, std::size_t& at) {
  while (at < s.size() && (isBlank(s[at]) || s[at] == '\n')) ++at;
  const std::size_t start = at;
  while (at < s.size() && !isBlank(s[at]) && s[at] != '\n') ++at;
  return s.substr(start, at - start);
}

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
  std::size_t at = 0;
  shape.keyword = nextToken(line, at);
  if (shape.keyword.empty()) return shape;
  while (!nextToken(line, at).empty()) ++shape.arguments;
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

// PLY's structure, walked before the importer reads the data. The header (up to end_header, whose
// presence findPlyHeaderProblem has checked) must be PLY's own -- keywords, scalar types: Turk's
// format as the importer knows it; an unknown keyword or type made the importer read the rows
// under another layout -- and its `element vertex N` and `element face N` counts are held against
// the limits. The importer also sizes each list by the count a row gives (a face row declaring
// 10^70 corners made it ask for 26 GB), so every list count, ASCII or binary, is held against
// maxPolygonVertices. Rows past the end of the bytes are the importer's to report.
struct PlyProperty {
  int countBytes = 0;  // a list's count type (0: a scalar)
  int itemBytes = 0;   // a scalar's type, or a list item's
  bool integerCount = true;
};
struct PlyElement {
  std::uint64_t count = 0;
  std::vector<PlyProperty> properties;
};

// Bytes of a PLY scalar type, 0 if the name is none; `integer` says whether it holds integers.
int plyTypeBytes(std::string_view type, bool& integer) {
  integer = true;
  if (type == "char" || type == "uchar" || type == "int8" || type == "uint8") return 1;
  if (type == "short" || type == "ushort" || type == "int16" || type == "uint16") return 2;
  if (type == "int" || type == "uint" || type == "int32" || type == "uint32") return 4;
  integer = false;
  if (type == "float" || type == "float32") return 4;
  if (type == "double" || type == "float64") return 8;
  return 0;
}

std::vector<std::string_view> tokensOf(std::string_view line) {
  std::vector<std::string_view> tokens;
  std::size_t at = 0;
  for (std::string_view t = nextToken(line, at); !t.empty(); t = nextToken(line, at)) tokens.push_back(t);
  return tokens;
}

void checkPly(std::string_view text, const std::string& source, const MeshLoadOptions& options) {
  std::vector<PlyElement> elements;
  enum class Encoding { kAscii, kLittle, kBig } encoding = Encoding::kAscii;
  std::size_t dataStart = text.size();
  forEachLine(text, [&](std::size_t lineNumber, std::string_view line) {
    auto bad = [&](const std::string& what) {
      throw Error(ErrorCode::kParseError, lineLabel(source, lineNumber) + ": PLY header: " + what);
    };
    const std::vector<std::string_view> t = tokensOf(line);
    if (t.empty()) return true;
    const std::string_view keyword = t[0];
    if (keyword == "end_header") {
      dataStart = std::min(std::size_t(line.data() - text.data()) + line.size() + 1, text.size());
      return false;
    }
    if (keyword == "ply" || keyword == "comment" || keyword == "obj_info") return true;
    if (keyword == "format") {
      if (t.size() < 2) bad("'format' without an encoding");
      if (t[1] == "ascii") encoding = Encoding::kAscii;
      else if (t[1] == "binary_little_endian") encoding = Encoding::kLittle;
      else if (t[1] == "binary_big_endian") encoding = Encoding::kBig;
      else bad("unknown encoding '" + std::string(t[1]) + "'");
    } else if (keyword == "element") {
      std::uint64_t count = 0;
      if (t.size() != 3 || std::from_chars(t[2].data(), t[2].data() + t[2].size(), count).ptr != t[2].data() + t[2].size())
        bad("'element' needs a name and a count");
      const std::string where = lineLabel(source, lineNumber);
      if (t[1] == "vertex") enforceLimit(count, options.maxVertices, "maxVertices", "vertices declared", where);
      else if (t[1] == "face") enforceLimit(count, options.maxTriangles, "maxTriangles", "faces declared", where);
      // Every vertex (3 coordinates) and face (a list) takes at least one byte in any encoding.
      if ((t[1] == "vertex" || t[1] == "face") && count > text.size())
        throw Error(ErrorCode::kParseError, where + ": " + std::to_string(count) + " " + std::string(t[1]) +
                                                " elements declared, more than a file of " +
                                                std::to_string(text.size()) + " bytes can hold");
      elements.push_back({count, {}});
    } else if (keyword == "property") {
      if (elements.empty()) bad("a property before any element");
      PlyProperty property;
      bool integer = false;
      if (t.size() == 5 && t[1] == "list") {
        property.countBytes = plyTypeBytes(t[2], property.integerCount);
        property.itemBytes = plyTypeBytes(t[3], integer);
        if (property.countBytes == 0 || property.itemBytes == 0 || !property.integerCount)
          bad("a list property needs an integer count type and an item type");
      } else if (t.size() == 3) {
        property.itemBytes = plyTypeBytes(t[1], integer);
        if (property.itemBytes == 0) bad("unknown type '" + std::string(t[1]) + "'");
      } else {
        bad("'property' needs a type and a name, or 'list', two types and a name");
      }
      elements.back().properties.push_back(property);
    } else {
      std::string shown(keyword.substr(0, 32));
      for (char& c : shown)
        if (c < 0x20 || c > 0x7e) c = '?';
      bad("unknown keyword '" + shown + "'");
    }
    return true;
  });
  const std::string where = source + ": PLY data";
  auto checkCount = [&](std::uint64_t corners) {
    enforceLimit(corners, options.maxPolygonVertices, "maxPolygonVertices", "entries in one list", where);
  };
  if (encoding == Encoding::kAscii) {
    std::size_t at = dataStart;
    for (const PlyElement& element : elements)
      for (std::uint64_t row = 0; row < element.count; ++row)
        for (const PlyProperty& property : element.properties) {
          const std::string_view token = nextToken(text, at);
          if (token.empty()) return;  // truncated: the importer's to report
          if (property.countBytes == 0) continue;
          std::uint64_t count = 0;
          const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), count);
          if (ec == std::errc::result_out_of_range) count = std::numeric_limits<std::uint64_t>::max();
          else if (ec != std::errc() || end != token.data() + token.size())
            throw Error(ErrorCode::kParseError, where + ": a list count is not a non-negative integer ('" +
                                                    std::string(token.substr(0, 32)) + "')");
          checkCount(count);
          for (std::uint64_t k = 0; k < count; ++k)
            if (nextToken(text, at).empty()) return;
        }
    return;
  }
  std::size_t at = dataStart;
  auto readCount = [&](int bytes) {
    std::uint64_t value = 0;
    for (int b = 0; b < bytes; ++b) {
      const int shift = encoding == Encoding::kLittle ? 8 * b : 8 * (bytes - 1 - b);
      value |= std::uint64_t(static_cast<unsigned char>(text[at + std::size_t(b)])) << shift;
    }
    at += std::size_t(bytes);
    return value;
  };
  for (const PlyElement& element : elements)
    for (std::uint64_t row = 0; row < element.count; ++row)
      for (const PlyProperty& property : element.properties) {
        if (property.countBytes == 0) {
          if (text.size() - at < std::size_t(property.itemBytes)) return;
          at += std::size_t(property.itemBytes);
          continue;
        }
        if (text.size() - at < std::size_t(property.countBytes)) return;
        std::uint64_t count = readCount(property.countBytes);
        // A signed count type's negative values read as huge ones here: refused either way.
        checkCount(count);
        const std::uint64_t bytes = count * std::uint64_t(property.itemBytes);
        if (text.size() - at < bytes) return;
        at += std::size_t(bytes);
      }
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
  if (looksLikePly(text)) checkPly(text, source, options);
  else if (format == "obj") checkObjCounts(text, source, options);
}

}  // namespace clod::detail
