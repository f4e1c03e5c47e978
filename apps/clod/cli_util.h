#pragma once
// Helpers shared by subcommands.

#include <nlohmann/json.hpp>

#include "clod/math.h"

namespace clod::cli {

inline nlohmann::json toJson(const Vec3& v) { return nlohmann::json::array({v.x(), v.y(), v.z()}); }

/// Prints a JSON document to stdout followed by a newline. Non-finite numbers print as null.
void printJson(const nlohmann::json& document);

}  // namespace clod::cli
