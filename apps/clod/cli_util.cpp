#include "cli_util.h"

#include <charconv>
#include <cmath>
#include <iostream>
#include <sstream>

#include <CLI/CLI.hpp>

#include "clod/error.h"

namespace clod::cli {

void printJson(const nlohmann::json& document) { std::cout << document.dump(2) << "\n"; }

std::uint64_t parseCountOption(std::string_view text, std::string_view flag, std::uint64_t lo, std::uint64_t hi) {
  std::uint64_t value = 0;
  // from_chars on digits alone: a sign, a space or a value past 2^64-1 is an error, not a wrap.
  const bool digits = !text.empty() && text.find_first_not_of("0123456789") == std::string_view::npos;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (!digits || ec != std::errc() || end != text.data() + text.size() || value < lo || value > hi) {
    throw Error(ErrorCode::kInvalidArgument, std::string(flag) + " '" + std::string(text) + "': expected an integer in [" +
                                                 std::to_string(lo) + ", " + std::to_string(hi) + "]");
  }
  return value;
}

double parseNumberOption(std::string_view text, std::string_view flag, double lo, double hi) {
  double value = 0.0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (text.empty() || ec != std::errc() || end != text.data() + text.size() || !std::isfinite(value) || value < lo ||
      value > hi) {
    std::ostringstream range;
    range << "[" << lo << ", " << hi << "]";
    throw Error(ErrorCode::kInvalidArgument,
                std::string(flag) + " '" + std::string(text) + "': expected a number in " + range.str());
  }
  return value;
}

std::string csvField(std::string_view text) {
  if (text.find_first_of(",\"\r\n") == std::string_view::npos) return std::string(text);
  std::string quoted = "\"";
  for (char c : text) {
    if (c == '"') quoted += '"';
    quoted += c;
  }
  quoted += '"';
  return quoted;
}

void addMeshLimitOptions(CLI::App* sub, MeshLoadOptions* limits) {
  const auto range = CLI::Range(std::uint64_t{1}, std::uint64_t{1} << 40);
  sub->add_option("--max-vertices", limits->maxVertices, "Refuse a mesh file with more vertices (before welding)")
      ->check(range)
      ->capture_default_str();
  sub->add_option("--max-triangles", limits->maxTriangles, "Refuse a mesh file with more triangles")
      ->check(range)
      ->capture_default_str();
  sub->add_option("--max-polygon-vertices", limits->maxPolygonVertices, "Refuse a mesh file with a polygon of more corners")
      ->check(range)
      ->capture_default_str();
}

}  // namespace clod::cli
