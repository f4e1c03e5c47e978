#include "text_index_check.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <iterator>
#include <cstring>
#include <vector>

namespace clod::detail {

namespace {

// Splits into lines (LF or CRLF), dropping '#' comments; calls f(lineNumber, tokens) for
// every line with at least one token. Returning false from f stops the scan.
template <class F>
void forEachTokenLine(std::string_view text, F&& f) {
  std::vector<std::string_view> tokens;
  std::size_t lineNumber = 0;
  std::size_t pos = 0;
  while (pos < text.size()) {
    std::size_t end = text.find('\n', pos);
    if (end == std::string_view::npos) end = text.size();
    std::string_view line = text.substr(pos, end - pos);
    pos = end + 1;
    ++lineNumber;
    if (auto hash = line.find('#'); hash != std::string_view::npos) line = line.substr(0, hash);
    tokens.clear();
    std::size_t i = 0;
    while (i < line.size()) {
      while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r')) ++i;
      std::size_t j = i;
      while (j < line.size() && line[j] != ' ' && line[j] != '\t' && line[j] != '\r') ++j;
      if (j > i) tokens.push_back(line.substr(i, j - i));
      i = j;
    }
    if (!tokens.empty() && !f(lineNumber, tokens)) return;
  }
}

std::optional<long long> parseInteger(std::string_view token) {
  long long value = 0;
  auto [ptr, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
  if (ec != std::errc() || ptr != token.data() + token.size()) return std::nullopt;
  return value;
}

}  // namespace

std::optional<std::string> findBadObjIndex(std::string_view text) {
  long long totalVertices = 0;
  forEachTokenLine(text, [&](std::size_t, const std::vector<std::string_view>& tokens) {
    if (tokens[0] == "v") ++totalVertices;
    return true;
  });
  long long verticesSoFar = 0;
  std::optional<std::string> result;
  forEachTokenLine(text, [&](std::size_t line, const std::vector<std::string_view>& tokens) {
    if (tokens[0] == "v") ++verticesSoFar;
    if (tokens[0] != "f" && tokens[0] != "l" && tokens[0] != "p") return true;
    for (std::size_t k = 1; k < tokens.size(); ++k) {
      std::string_view corner = tokens[k].substr(0, tokens[k].find('/'));  // v/vt/vn: the position index
      auto index = parseInteger(corner);
      if (!index) continue;
      // OBJ indices are 1-based; negative ones count back from the latest vertex.
      const long long resolved = *index > 0 ? *index : verticesSoFar + *index + 1;
      if (*index == 0 || resolved < 1 || resolved > totalVertices) {
        result = "line " + std::to_string(line) + ": vertex index " + std::string(corner) +
                 (*index > 0 ? " > vertex count " + std::to_string(totalVertices)
                             : " does not refer to a vertex (" + std::to_string(verticesSoFar) + " defined so far)");
        return false;
      }
    }
    return true;
  });
  return result;
}

bool looksLikePly(std::string_view text) {
  std::size_t i = 0;
  // Assimp drops NUL bytes before it looks for the "ply" token: "\0\nply" without an end_header
  // hung its PLY reader (a fuzz finding).
  while (i < text.size() && (text[i] == ' ' || text[i] == '\t' || text[i] == '\r' || text[i] == '\n' || text[i] == '\0')) ++i;
  if (text.size() - i < 3) return false;
  auto lower = [](char c) { return c >= 'A' && c <= 'Z' ? char(c - 'A' + 'a') : c; };
  return lower(text[i]) == 'p' && lower(text[i + 1]) == 'l' && lower(text[i + 2]) == 'y';
}

std::optional<std::string> findPlyHeaderProblem(std::string_view text) {
  if (!looksLikePly(text)) return std::nullopt;
  std::size_t pos = 0;
  while (pos < text.size()) {
    std::size_t end = text.find('\n', pos);
    if (end == std::string_view::npos) end = text.size();
    std::string_view line = text.substr(pos, end - pos);
    while (!line.empty() && (line.back() == '\r' || line.back() == ' ' || line.back() == '\t')) line.remove_suffix(1);
    if (line == "end_header") return std::nullopt;
    pos = end + 1;
  }
  return "PLY header has no 'end_header' line";
}

bool looksLikeGlb(std::string_view bytes) { return bytes.size() >= 4 && bytes.substr(0, 4) == "glTF"; }

std::optional<std::string> findGlbHeaderProblem(std::string_view bytes) {
  if (!looksLikeGlb(bytes)) return std::nullopt;
  // Little-endian u32 fields (glTF 2.0 spec, "Binary glTF Layout"): magic, version, length, then
  // chunks of (length, type, data).
  auto u32 = [&](std::size_t offset) {
    const auto* p = reinterpret_cast<const unsigned char*>(bytes.data() + offset);
    return std::uint64_t(p[0]) | std::uint64_t(p[1]) << 8 | std::uint64_t(p[2]) << 16 | std::uint64_t(p[3]) << 24;
  };
  if (bytes.size() < 12) return "GLB header is truncated (" + std::to_string(bytes.size()) + " bytes)";
  const std::uint64_t declared = u32(8);
  if (declared > bytes.size())
    return "GLB header declares " + std::to_string(declared) + " bytes, the file has " + std::to_string(bytes.size());
  std::uint64_t offset = 12;
  for (int chunk = 0; offset + 8 <= declared; ++chunk) {
    const std::uint64_t length = u32(std::size_t(offset));
    if (offset + 8 + length > declared)
      return "GLB chunk " + std::to_string(chunk) + " declares " + std::to_string(length) + " bytes, only " +
             std::to_string(declared - offset - 8) + " remain";
    offset += 8 + length;
  }
  return std::nullopt;
}

bool looksLikeJson(std::string_view text) {
  if (text.substr(0, 3) == "\xEF\xBB\xBF") text.remove_prefix(3);
  const std::size_t first = text.find_first_not_of(" \t\r\n");
  return first != std::string_view::npos && text[first] == '{';
}

std::optional<std::string_view> glbJsonChunk(std::string_view bytes) {
  if (!looksLikeGlb(bytes) || bytes.size() < 20) return std::nullopt;
  auto u32 = [&](std::size_t offset) {
    const auto* p = reinterpret_cast<const unsigned char*>(bytes.data() + offset);
    return std::uint32_t(p[0]) | std::uint32_t(p[1]) << 8 | std::uint32_t(p[2]) << 16 | std::uint32_t(p[3]) << 24;
  };
  constexpr std::uint32_t kJsonChunkType = 0x4E4F534A;  // "JSON", little-endian
  const std::uint64_t length = u32(12);
  if (u32(16) != kJsonChunkType || 20 + length > bytes.size()) return std::nullopt;
  return bytes.substr(20, std::size_t(length));
}

std::optional<std::string> findJsonDepthProblem(std::string_view json, std::uint32_t maxDepth) {
  std::uint64_t depth = 0;
  bool inString = false, escaped = false;
  for (std::size_t i = 0; i < json.size(); ++i) {
    const char c = json[i];
    if (inString) {
      if (escaped) escaped = false;
      else if (c == '\\') escaped = true;
      else if (c == '"') inString = false;
    } else if (c == '"') {
      inString = true;
    } else if (c == '[' || c == '{') {
      if (++depth > maxDepth)
        return "JSON nests deeper than " + std::to_string(maxDepth) + " levels (at byte " + std::to_string(i) +
               "; MeshLoadOptions::maxJsonDepth)";
    } else if ((c == ']' || c == '}') && depth > 0) {
      --depth;
    }
  }
  return std::nullopt;
}

bool looksLikeCollada(std::string_view text) { return text.find("<COLLADA") != std::string_view::npos; }

namespace {

// A Collada array's `count` attribute against the number of values it holds: Assimp 5.2.5 sizes
// the array by `count` and its accessors then read an empty one (a <float_array> without
// `count`, or with count 0, -1 or "abc", crashed its Collada reader: fuzz_mesh_load).
std::optional<std::string> arrayCountProblem(std::string_view name, std::size_t at, std::string_view attributes,
                                             std::size_t values) {
  const std::string where = "Collada <" + std::string(name) + "> at byte " + std::to_string(at);
  std::size_t key = attributes.find("count");
  while (key != std::string_view::npos && key > 0 && !std::isspace(static_cast<unsigned char>(attributes[key - 1])))
    key = attributes.find("count", key + 1);
  if (key == std::string_view::npos) return where + " has no count attribute";
  std::size_t k = key + 5;
  while (k < attributes.size() && std::isspace(static_cast<unsigned char>(attributes[k]))) ++k;
  if (k >= attributes.size() || attributes[k] != '=') return where + " has no count attribute";
  ++k;
  while (k < attributes.size() && std::isspace(static_cast<unsigned char>(attributes[k]))) ++k;
  const char quote = k < attributes.size() ? attributes[k] : '\0';
  const std::size_t close = quote == '"' || quote == '\'' ? attributes.find(quote, k + 1) : std::string_view::npos;
  const std::string_view digits = close == std::string_view::npos ? std::string_view() : attributes.substr(k + 1, close - k - 1);
  const bool number = !digits.empty() && digits.size() <= 18 &&
                      std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; });
  if (!number) return where + " has a count that is not a whole number";
  const std::size_t count = std::stoull(std::string(digits));
  if (count == 0 || count != values)
    return where + " says count=\"" + std::string(digits) + "\" but holds " + std::to_string(values) + " values";
  return std::nullopt;
}

}  // namespace

std::optional<std::string> findColladaNumberListProblem(std::string_view text) {
  if (!looksLikeCollada(text)) return std::nullopt;
  static constexpr std::string_view kLists[] = {"p", "vcount", "v", "h", "int_array", "float_array"};
  // Index lists hold integers; only <float_array> holds reals.
  auto numberChar = [](char c, bool real) {
    if ((c >= '0' && c <= '9') || c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '-') return true;
    return real && (c == '+' || c == '.' || c == 'e' || c == 'E');
  };
  for (std::size_t at = text.find('<'); at != std::string_view::npos; at = text.find('<', at + 1)) {
    std::size_t nameEnd = at + 1;
    while (nameEnd < text.size() && (std::isalnum(static_cast<unsigned char>(text[nameEnd])) || text[nameEnd] == '_'))
      ++nameEnd;
    const std::string_view name = text.substr(at + 1, nameEnd - at - 1);
    if (std::find(std::begin(kLists), std::end(kLists), name) == std::end(kLists)) continue;
    if (nameEnd < text.size() && text[nameEnd] != '>' && !std::isspace(static_cast<unsigned char>(text[nameEnd])) &&
        text[nameEnd] != '/')
      continue;
    const std::size_t tagEnd = text.find('>', nameEnd);
    if (tagEnd == std::string_view::npos) return std::nullopt;  // truncated: Assimp's verdict
    const bool array = name.ends_with("_array");
    if (text[tagEnd - 1] == '/') {  // an empty element
      if (array) return arrayCountProblem(name, at, text.substr(nameEnd, tagEnd - nameEnd), 0);
      continue;
    }
    const bool real = name == "float_array";
    std::size_t values = 0;
    bool inValue = false;
    for (std::size_t k = tagEnd + 1; k < text.size() && text[k] != '<'; ++k) {
      if (!numberChar(text[k], real)) {
        return "Collada <" + std::string(name) + "> at byte " + std::to_string(at) +
               " holds a character that is not part of a number (byte " + std::to_string(k) + ", code " +
               std::to_string(static_cast<unsigned char>(text[k])) + ")";
      }
      const bool space = std::isspace(static_cast<unsigned char>(text[k])) != 0;
      values += !space && !inValue;
      inValue = !space;
    }
    if (array)
      if (auto problem = arrayCountProblem(name, at, text.substr(nameEnd, tagEnd - nameEnd), values)) return problem;
  }
  return std::nullopt;
}

}  // namespace clod::detail
