#pragma once
// Command-line parsing shared by the comparison programs (world_compare, bullet_compare): comma
// lists, counts ("unlimited" = 0) and non-negative numbers, with a UsageError naming the flag.

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

namespace bench {

struct UsageError {
  std::string message;
};

inline std::vector<std::string> splitList(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ','))
    if (!item.empty()) out.push_back(item);
  return out;
}

inline std::uint64_t parseCount(const std::string& flag, const std::string& text) {
  if (text == "unlimited") return 0;
  char* end = nullptr;
  const unsigned long long v = std::strtoull(text.c_str(), &end, 10);
  if (text.empty() || *end != '\0' || text[0] == '-') throw UsageError{flag + ": expected a count, got '" + text + "'"};
  return v;
}

inline double parsePositive(const std::string& flag, const std::string& text) {
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0' || !(v >= 0.0) || !std::isfinite(v)) throw UsageError{flag + ": expected a number >= 0"};
  return v;
}

}  // namespace bench
