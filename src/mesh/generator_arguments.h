#pragma once
// Argument checks shared by the mesh generators (part_meshes.cpp, thread_meshes.cpp): a bad
// dimension or count is the caller's error, reported with its name and value.
#include <cmath>
#include <cstdint>
#include <string>

#include "clod/error.h"

namespace clod::detail {

inline void requirePositive(double value, const std::string& name) {
  if (!(value > 0.0) || !std::isfinite(value))
    throw Error(ErrorCode::kInvalidArgument, name + " " + std::to_string(value) + " is not a positive finite number");
}

inline void requireCount(std::uint32_t value, std::uint32_t lo, std::uint32_t hi, const std::string& name) {
  if (value < lo || value > hi)
    throw Error(ErrorCode::kInvalidArgument, name + " " + std::to_string(value) + " not in [" + std::to_string(lo) +
                                                 ", " + std::to_string(hi) + "]");
}

}  // namespace clod::detail
