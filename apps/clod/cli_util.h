#pragma once
// Helpers shared by subcommands.

#include <cstdint>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "clod/math.h"
#include "clod/mesh_io.h"

namespace CLI {
class App;
}

namespace clod::cli {

/// --max-vertices, --max-triangles, --max-polygon-vertices: the mesh loader's resource limits
/// (MeshLoadOptions), written into `limits` when given; for every command that loads a mesh file.
void addMeshLimitOptions(CLI::App* sub, MeshLoadOptions* limits);

inline nlohmann::json toJson(const Vec3& v) { return nlohmann::json::array({v.x(), v.y(), v.z()}); }

/// Prints a JSON document to stdout followed by a newline. Non-finite numbers print as null.
void printJson(const nlohmann::json& document);

/// An option's text as an integer in [lo, hi]: decimal digits only (no sign, no spaces), so
/// "-1" and "18446744073709551616" (2^64) are refused rather than wrapped. Throws
/// clod::Error(kInvalidArgument) naming the flag and the accepted range (exit 2).
std::uint64_t parseCountOption(std::string_view text, std::string_view flag, std::uint64_t lo, std::uint64_t hi);

/// An option's text as a finite number in [lo, hi]; throws like parseCountOption.
double parseNumberOption(std::string_view text, std::string_view flag, double lo, double hi);

/// One CSV field as RFC 4180 writes it: unchanged when it holds no comma, double quote, CR or
/// LF; otherwise in double quotes with each double quote doubled ("a,b" -> "\"a,b\"").
std::string csvField(std::string_view text);

}  // namespace clod::cli
