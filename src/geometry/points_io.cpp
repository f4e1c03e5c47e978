#include "clod/points_io.h"

#include <charconv>
#include <cmath>
#include <cstdlib>
#include <string>
#include <system_error>

#include "clod/atomic_file.h"
#include "clod/error.h"

namespace clod {
namespace {

bool isSpace(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

// Tokens go into error messages: keep them short and printable so a binary file cannot
// flood the terminal or hide part of the message.
std::string quoteToken(std::string_view token) {
  constexpr std::size_t kMaxShown = 32;
  std::string out = "'";
  for (std::size_t i = 0; i < token.size() && i < kMaxShown; ++i) {
    const unsigned char c = static_cast<unsigned char>(token[i]);
    if (c >= 0x20 && c < 0x7f) {
      out += static_cast<char>(c);
    } else {
      static const char* kHex = "0123456789abcdef";
      out += "\\x";
      out += kHex[c >> 4];
      out += kHex[c & 15];
    }
  }
  if (token.size() > kMaxShown) out += "...";
  return out + "'";
}

double parseNumber(std::string_view token, std::size_t line) {
  std::string_view digits = token;
  // std::from_chars rejects a leading '+', which people do write.
  if (digits.size() > 1 && digits.front() == '+' && digits[1] != '-' && digits[1] != '+') digits.remove_prefix(1);
  double value = 0.0;
  const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
  const std::string where = "line " + std::to_string(line) + ": ";
  if (ec == std::errc::result_out_of_range && end == digits.data() + digits.size()) {
    // Out of range is either overflow (an infinite coordinate: reject) or underflow (a
    // coordinate below the smallest double: strtod's nearest value, 0 or subnormal, is right).
    const std::string copy(digits);
    const double nearest = std::strtod(copy.c_str(), nullptr);
    if (std::isfinite(nearest) && std::fabs(nearest) < 1.0) return nearest;
    throw Error(ErrorCode::kNonFiniteVertex, where + "number " + quoteToken(token) + " overflows a double");
  }
  if (ec != std::errc() || end != digits.data() + digits.size()) {
    throw Error(ErrorCode::kParseError, where + "expected a number, found " + quoteToken(token));
  }
  if (!std::isfinite(value)) {
    throw Error(ErrorCode::kNonFiniteVertex, where + "coordinate " + quoteToken(token) + " is not finite");
  }
  return value;
}

}  // namespace

std::vector<Vec3> parsePoints(std::string_view text) {
  std::vector<Vec3> points;
  std::size_t lineNumber = 0;
  std::size_t pos = 0;
  while (pos < text.size()) {
    ++lineNumber;
    std::size_t lineEnd = text.find('\n', pos);
    if (lineEnd == std::string_view::npos) lineEnd = text.size();
    std::string_view line = text.substr(pos, lineEnd - pos);
    pos = lineEnd + 1;
    if (const std::size_t hash = line.find('#'); hash != std::string_view::npos) line = line.substr(0, hash);

    double coordinates[3];
    std::size_t count = 0;  // numbers on this line
    std::size_t i = 0;
    while (i < line.size()) {
      while (i < line.size() && isSpace(line[i])) ++i;
      if (i == line.size()) break;
      std::size_t j = i;
      while (j < line.size() && !isSpace(line[j])) ++j;
      coordinates[count % 3] = parseNumber(line.substr(i, j - i), lineNumber);
      ++count;
      if (count % 3 == 0) points.emplace_back(coordinates[0], coordinates[1], coordinates[2]);
      i = j;
    }
    if (count % 3 != 0) {
      throw Error(ErrorCode::kParseError, "line " + std::to_string(lineNumber) + ": expected x y z, found " +
                                              std::to_string(count) + (count == 1 ? " number" : " numbers"));
    }
  }
  return points;
}

std::vector<Vec3> readPointsFile(const std::filesystem::path& path) {
  const std::string text = readWholeFile(path);
  if (text.empty()) throw Error(ErrorCode::kEmptyFile, "'" + path.string() + "' is empty (no points)");
  try {
    return parsePoints(text);
  } catch (const Error& e) {
    throw Error(e.code(), "'" + path.string() + "', " + e.what());
  }
}

}  // namespace clod
