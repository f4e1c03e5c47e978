#pragma once
// Checks on the raw text of OBJ, OFF and PLY files, run next to Assimp because Assimp either
// rejects an out-of-range index without saying where (OBJ: "vertex index out of range"),
// silently repairs it (OFF: clamps it to the last vertex; negative indices parse as 0), or
// never returns (PLY: a header without an `end_header` line loops forever in Assimp 5.2.5).
// These scanners read only what they need; they are not loaders, and on anything they do not
// understand they return std::nullopt and leave the verdict to Assimp.

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace clod::detail {

/// What findBadOffFace found.
struct OffProblem {
  bool indexOutOfRange;  ///< true: an index is negative or >= vertex count; false: a face lists no vertex
  std::string message;   ///< names the line, e.g. "line 9: face 1: vertex index 9001 >= vertex count 3"
};

/// First face of an OFF text with an out-of-range or negative index, or with no vertices at all
/// (Assimp 5.2.5 crashes on that); nullopt when all faces are fine or the text is not plain
/// (ST)(C)(N)OFF. O(size).
std::optional<OffProblem> findBadOffFace(std::string_view text);

/// First face/line/point index of an OBJ text that refers to a vertex that does not exist
/// (positive index > number of `v` lines in the file, negative index reaching before the first
/// vertex, or 0), as a message naming the line; nullopt when none. O(size).
std::optional<std::string> findBadObjIndex(std::string_view text);

/// True when the bytes start (after whitespace) with the PLY magic "ply", case-insensitive:
/// Assimp hands such content to its PLY reader whatever the extension says.
bool looksLikePly(std::string_view text);

/// For PLY content (looksLikePly), a message when the header has no line reading exactly
/// `end_header` (trailing spaces and CR allowed), which would hang Assimp's PLY reader; nullopt
/// otherwise. O(size).
std::optional<std::string> findPlyHeaderProblem(std::string_view text);

}  // namespace clod::detail
