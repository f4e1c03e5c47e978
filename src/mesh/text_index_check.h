#pragma once
// Index checks on the text of OBJ and OFF files, run next to Assimp because Assimp either
// rejects an out-of-range index without saying where (OBJ: "vertex index out of range") or
// silently repairs it (OFF: clamps it to the last vertex; negative indices parse as 0).
// These scanners read only what they need to find indices; they are not loaders, and on
// anything they do not understand they return std::nullopt and leave the verdict to Assimp.

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace clod::detail {

/// First out-of-range or negative face index in an OFF text, as a message naming the line,
/// e.g. "line 9: face 1: vertex index 9001 >= vertex count 3"; nullopt when all are in range or
/// the text is not plain (ST)(C)(N)OFF. O(size).
std::optional<std::string> findBadOffIndex(std::string_view text);

/// First face/line/point index of an OBJ text that refers to a vertex that does not exist
/// (positive index > number of `v` lines in the file, negative index reaching before the first
/// vertex, or 0), as a message naming the line; nullopt when none. O(size).
std::optional<std::string> findBadObjIndex(std::string_view text);

}  // namespace clod::detail
